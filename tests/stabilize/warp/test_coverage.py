"""The zoom that hides every border: single frames and the vectorised search."""

import numpy as np

from rotation import so3
from rotation.camera import intrinsics
from stabilize.warp.coverage import Framing
from stabilize.warp.homography import homography
from tests.stabilize.helpers import covers, required_zoom

K = intrinsics(500.0, (360, 640))
SIZE = (360, 640)


def test_zoom_of_identity_and_of_a_turn():
    assert required_zoom(K, np.eye(3), SIZE) == 1.0
    turn = so3.exp_so3([0.0, np.radians(3.0), 0.0])
    z = required_zoom(K, turn, SIZE)
    assert 1.0 < z < 1.5
    assert covers(K, turn, z + 1e-6, SIZE) and not covers(K, turn, z - 1e-3, SIZE)
    H = homography(K, np.eye(3), 2.0)
    np.testing.assert_allclose(H @ [K[0, 2], K[1, 2], 1.0], [K[0, 2], K[1, 2], 1.0])


def test_the_vectorised_zoom_search_finds_the_least_covering_zoom():
    K = intrinsics(400.0, (180, 320))
    rng = np.random.default_rng(3)
    C = so3.exp_so3(rng.normal(0, 0.03, (20, 3)))
    C[0] = np.eye(3)
    C[1] = so3.exp_so3([0.0, 0.6, 0.0])  # too far for the zoom limit
    zooms = Framing(K, (180, 320)).required_zooms(C, 1.5)
    assert zooms[0] == 1.0 and np.isinf(zooms[1])
    checked = 0
    for c, z in zip(C[2:], zooms[2:], strict=True):
        if 1.0 < z < np.inf:
            assert covers(K, c, z, (180, 320)) and not covers(K, c, z - 1e-4, (180, 320))
            checked += 1
    assert checked >= 5


def test_the_middle_jacobian_is_the_zoom_and_a_turns_foreshortening():
    theta = 0.2
    turn = so3.exp_so3([0.0, theta, 0.0])
    J = Framing(K, SIZE).middle_jacobian(np.stack([np.eye(3), turn]), np.array([1.25, 1.0]))
    np.testing.assert_allclose(J[0], np.eye(2) / 1.25, atol=1e-9)  # output → input
    s = np.linalg.svd(J[1], compute_uv=False)
    # across the turn's axis the frame is foreshortened by cos θ: a keystone
    np.testing.assert_allclose(s[1] / s[0], np.cos(theta), atol=1e-5)
    # a 2-D shift after the turn moves where its foreshortening is read: back by f tan θ
    # (the middle's source the input's middle) it stays cos θ, the other way it grows
    back = np.array([[1.0, 0.0, -np.tan(theta)], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    further = np.linalg.inv(back)
    J = Framing(K, SIZE).middle_jacobian(np.stack([back @ turn, further @ turn]), np.ones(2))
    s = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_allclose(
        s[:, 1] / s[:, 0], [np.cos(theta), np.cos(2 * theta) / np.cos(theta)], atol=1e-4
    )
