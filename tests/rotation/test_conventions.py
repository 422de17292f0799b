"""CONVENTIONS.md pinned: R_t maps frame-t rays to frame-(t+1) rays; (A, B, C) = -rotvec(R_t)."""

import numpy as np
import pytest

from rotation import HoughEstimator, so3
from rotation.models import lh_line
from rotation.synthetic import rotation_flow

SIZE = (270, 480)
F = 413.75


def pan_right(deg: float) -> np.ndarray:
    """R_t of a camera that turns right (its optical axis towards +x) by ``deg``."""
    camera_motion = so3.exp_so3([0.0, np.radians(deg), 0.0])  # z turns towards +x
    return camera_motion.T  # R_t is the inverse of the camera's own rotation


def test_panning_right_moves_content_left():
    flow = rotation_flow(pan_right(1.0), F, SIZE)
    assert np.all(flow[..., 0] < 0)
    assert flow[134, 239, 0] == pytest.approx(-F * np.tan(np.radians(1.0)), rel=1e-3)


@pytest.mark.parametrize("model", ["longuet-higgins", "perspective"])
def test_estimate_returns_R_t_for_a_right_pan(model):
    R = pan_right(1.0)
    est = HoughEstimator(SIZE, F, model=model).estimate(rotation_flow(R, F, SIZE))
    np.testing.assert_allclose(est.rotvec, [0.0, -np.radians(1.0), 0.0], atol=1e-8)
    np.testing.assert_allclose(est.matrix, R, atol=1e-8)


@pytest.mark.parametrize("model", ["longuet-higgins", "perspective"])
def test_tilt_and_roll_signs(model):
    rotvec = np.radians([0.7, -0.4, 1.1])
    R = so3.exp_so3(rotvec)
    est = HoughEstimator(SIZE, F, model=model).estimate(rotation_flow(R, F, SIZE))
    np.testing.assert_allclose(est.rotvec, rotvec, atol=1e-8)


def test_longuet_higgins_abc_is_the_camera_rotation():
    # A small pure-rotation flow vector's line passes through (A, B, C) = -rotvec(R_t).
    omega = np.radians([0.3, -0.2, 0.5])
    flow = rotation_flow(so3.exp_so3(-omega), F, SIZE)
    x, y = 100.0 - 239.5, 50.0 - 134.5
    a0, b0, da, db = lh_line(x, y, *flow[50, 100].astype(float), F)
    C = omega[2]
    # First-order model: equal to within a percent, and of the same sign.
    np.testing.assert_allclose([a0 + C * da, b0 + C * db], omega[:2], rtol=0.02)
    assert (da, db) == (x / F, y / F)
