import numpy as np

from rotation import so3


def test_exp_log_round_trip_small_and_large_angles():
    rng = np.random.default_rng(0)
    axes = rng.normal(size=(50, 3))
    w = axes / np.linalg.norm(axes, axis=1, keepdims=True) * np.geomspace(1e-9, 3.0, 50)[:, None]
    np.testing.assert_allclose(so3.log_so3(so3.exp_so3(w)), w, atol=1e-12, rtol=1e-9)


def test_exp_is_right_handed():
    # A quarter turn about +z takes +x to +y.
    R = so3.exp_so3([0.0, 0.0, np.pi / 2])
    np.testing.assert_allclose(R @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)


def test_angular_error_is_the_angle_of_the_difference():
    R = so3.exp_so3([0.01, -0.02, 0.005])
    dR = so3.exp_so3([0.0, 0.0, np.radians(0.3)])
    assert np.isclose(so3.angular_error_deg(dR @ R, R), 0.3)
    assert so3.angular_error_deg(R, R) < 1e-7


def test_random_rotations_respect_angle_range():
    Rs = so3.random_rotations(np.random.default_rng(1), 100, 2.0, 1.0)
    angles = np.degrees(so3.angle(Rs))
    assert angles.min() >= 1.0 - 1e-9 and angles.max() <= 2.0 + 1e-9
