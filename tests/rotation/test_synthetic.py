import numpy as np

from rotation import so3
from rotation.synthetic import Street, corrupt, make_set, random_people, rotation_flow, street_flow

SIZE = (90, 160)
F = 138.0


def test_rotation_flow_matches_the_homography():
    R = so3.exp_so3([0.01, -0.02, 0.03])
    flow = rotation_flow(R, F, SIZE)
    K = np.array([[F, 0, 79.5], [0, F, 44.5], [0, 0, 1]])
    p = np.array([10.0, 20.0, 1.0])
    q = K @ R @ np.linalg.inv(K) @ p
    np.testing.assert_allclose(p[:2] + flow[20, 10], q[:2] / q[2], atol=1e-4)


def test_street_without_translation_is_pure_rotation():
    R = so3.exp_so3([0.0, 0.02, 0.0])
    flow = street_flow(R, np.zeros(3), F, SIZE, Street())
    np.testing.assert_allclose(flow, rotation_flow(R, F, SIZE), atol=1e-4)


def test_translation_moves_near_points_and_not_the_sky():
    T = np.array([0.0, 0.0, 0.5])
    flow = street_flow(np.eye(3), T, F, SIZE, Street(walls=False))
    assert np.abs(flow[5, 80]).max() < 1e-6  # above the horizon: at infinity
    assert flow[-1, 80, 1] > 1.0  # ground just below the camera flows downwards


def test_people_move_with_their_own_velocity():
    rng = np.random.default_rng(0)
    people = random_people(rng, 5, Street())
    still = street_flow(np.eye(3), np.zeros(3), F, SIZE, Street(), None)
    moving = street_flow(np.eye(3), np.zeros(3), F, SIZE, Street(), people)
    changed = np.abs(moving - still).max(axis=-1) > 1e-3
    assert 0 < changed.mean() < 0.5


def test_corrupt_replaces_the_requested_share():
    rng = np.random.default_rng(0)
    flow = np.zeros((100, 100, 2), np.float32)
    out = corrupt(rng, flow, gross_fraction=0.3)
    assert abs((np.abs(out).sum(-1) > 0).mean() - 0.3) < 0.03


def test_sets_are_deterministic():
    a = make_set("street", 2, seed=4, size=SIZE, focal=F)
    b = make_set("street", 2, seed=4, size=SIZE, focal=F)
    np.testing.assert_array_equal(a.flows, b.flows)
    np.testing.assert_array_equal(a.rotations, b.rotations)
