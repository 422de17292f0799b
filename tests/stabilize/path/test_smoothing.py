"""Smoothing on SO(3): the orientation chain, the methods, the pans they keep."""

import numpy as np
import pytest

from rotation import so3
from stabilize.path.smoothing import orientations_from_rotations, smooth_orientations
from tests.stabilize.helpers import shaky_path


def test_orientations_chain_the_rotations():
    R = so3.random_rotations(np.random.default_rng(1), 5, 2.0)
    O = orientations_from_rotations(R)
    np.testing.assert_allclose(O[3] @ O[2].T, R[2], atol=1e-12)
    np.testing.assert_allclose(O[0], np.eye(3))


def test_gaussian_smoothing_removes_shake_and_keeps_a_pan():
    t, O = shaky_path(pan_deg_s=10.0)
    S = smooth_orientations(O, t, 0.5, "gaussian")
    jitter = lambda P: np.degrees(so3.angle(P[1:] @ np.swapaxes(P[:-1], -1, -2))).std()  # noqa: E731
    assert jitter(S) < 0.1 * jitter(O)
    yaw = np.degrees(so3.log_so3(np.swapaxes(S, -1, -2))[:, 1])
    assert yaw[-10] - yaw[10] == pytest.approx(10.0 * (t[-10] - t[10]), rel=0.15)


def test_lock_holds_one_orientation():
    t, O = shaky_path()
    S = smooth_orientations(O, t, method="lock")
    assert np.allclose(S, S[0])
