"""The image motion a rotation leaves: recovered on the background, crowds ignored."""

import numpy as np
import pytest

from rotation import so3
from stabilize.motion.residual import GATE_PX, gate_px, reexpress, residual_motion

F = 400.0


def _grid():
    xs, ys = np.meshgrid(np.arange(-300.0, 301.0, 15.0), np.arange(-170.0, 171.0, 15.0))
    return xs.ravel(), ys.ravel()


def _flow(x, y, R, shift, scale=0.0):
    """Flow of points turned by R, then moved by ``shift`` px and zoomed by 1+scale."""
    rays = np.stack([x, y, np.full_like(x, F)], 1) @ R.T
    px, py = F * rays[:, 0] / rays[:, 2], F * rays[:, 1] / rays[:, 2]
    return px + shift[0] + scale * px - x, py + shift[1] + scale * py - y


def test_a_translation_left_after_the_rotation_is_recovered():
    x, y = _grid()
    R = so3.exp_so3(np.array([0.01, -0.02, 0.004]))
    u, v = _flow(x, y, R, (2.0, -1.5))
    rng = np.random.default_rng(0)
    u, v = u + rng.normal(0, 0.2, u.shape), v + rng.normal(0, 0.2, v.shape)
    valid = np.ones((1, len(x)), bool)
    dx, dy, a, b = residual_motion(x, y, u[None], v[None], valid, R[None], F)[0]
    assert dx * F == pytest.approx(2.0, abs=0.03) and dy * F == pytest.approx(-1.5, abs=0.03)
    assert abs(a) < 1e-4 and abs(b) < 1e-4


def test_a_near_wall_passing_4_px_a_frame_is_background():
    """A walk's sway past a wall that fills the frame: static, so its 4 px a frame (at
    the flow's size; hero7's near plants loom about 3) is the camera's, to be undone.
    A 3 px gate left such a pair with no motion at all."""
    dx, dy = _past_a_wall(4.0, seed=1)
    assert dx == pytest.approx(4.0, abs=0.05) and abs(dy) < 0.05


def _past_a_wall(shift: float, seed: int, gate: float = GATE_PX) -> tuple[float, float]:
    """The translation (px) fitted within ``gate`` to a pair turned a little and moved
    ``shift`` px to the right, as a wall that fills the frame moves past, with 0.2 px
    of flow noise."""
    x, y = _grid()
    R = so3.exp_so3(np.array([0.004, -0.01, 0.0]))
    u, v = _flow(x, y, R, (shift, 0.0))
    rng = np.random.default_rng(seed)
    u, v = u + rng.normal(0, 0.2, u.shape), v + rng.normal(0, 0.2, v.shape)
    valid = np.ones((1, len(x)), bool)
    dx, dy, _, _ = residual_motion(x, y, u[None], v[None], valid, R[None], F, gate)[0]
    return dx * F, dy * F


def test_the_gate_widens_with_the_time_between_frames():
    """Parallax and a subject's motion both grow with the time a pair spans: a clip at
    half the rate has twice of each, and its gate is twice as wide. Faster rates keep
    the gate (strides of a thirtieth of a second measure them too)."""
    for fps in (30.0, 30000 / 1001, 60.0, 240.0):
        assert gate_px(np.arange(20) / fps) == GATE_PX
    assert gate_px(np.arange(20) * 1001 / 15000) == 2 * GATE_PX  # 14.985 fps
    assert gate_px(np.arange(20) / 20.0) == pytest.approx(GATE_PX * 30000 / 1001 / 20, abs=0.01)
    dropped = np.delete(np.arange(40) * 1001 / 15000, [5, 17])  # the median, not a dropped frame's
    assert gate_px(dropped) == 2 * GATE_PX
    assert gate_px(np.zeros(5)) == GATE_PX and gate_px(np.array([0.0])) == GATE_PX


def test_a_near_wall_at_half_the_rate_is_background_within_its_gate():
    """The near wall's 4 px a frame at 30 fps is 8 px at 15: outside a 30 fps pair's gate,
    where the pair's fit is left to the few vectors nearer the rotation's prediction;
    inside the gate of a pair that spans a fifteenth of a second."""
    dx, dy = _past_a_wall(8.0, seed=2, gate=gate_px(np.arange(10) / 15.0))
    assert dx == pytest.approx(8.0, abs=0.05) and abs(dy) < 0.05
    assert _past_a_wall(8.0, seed=2)[0] < 1.0  # a 30 fps pair's gate


def test_a_crowd_moving_across_the_frame_does_not_drag_the_background():
    x, y = _grid()
    R = so3.exp_so3(np.array([0.0, 0.015, 0.0]))
    u, v = _flow(x, y, R, (0.8, 0.0))
    crowd = (x > 0) & (y > -60)  # a third of the frame walks right at 6 px a frame
    assert 0.25 < crowd.mean() < 0.4
    u[crowd] += 6.0
    valid = np.ones((1, len(x)), bool)
    dx, dy, _, _ = residual_motion(x, y, u[None], v[None], valid, R[None], F)[0]
    assert dx * F == pytest.approx(0.8, abs=0.05) and abs(dy * F) < 0.05
    # Without the gate and the Cauchy weights, least squares follows the crowd:
    mean_dx = np.mean(u - _flow(x, y, R, (0.0, 0.0))[0])
    assert mean_dx > 2.0


def test_too_few_vectors_give_no_motion():
    x, y = _grid()
    u, v = _flow(x, y, np.eye(3), (1.0, 1.0))
    valid = np.zeros((1, len(x)), bool)
    valid[0, :10] = True
    assert not residual_motion(x, y, u[None], v[None], valid, np.eye(3)[None], F).any()


def test_a_residual_reexpressed_after_another_rotation_matches_one_measured_after_it():
    x, y = _grid()
    R_true = so3.exp_so3(np.array([0.01, 0.02, -0.003]))
    u, v = _flow(x, y, R_true, (1.0, 0.5))
    valid = np.ones((1, len(x)), bool)
    R_other = so3.exp_so3(np.array([0.011, 0.019, -0.003]))  # a gyro's, say: 0.08° off
    direct = residual_motion(x, y, u[None], v[None], valid, R_other[None], F)
    measured = residual_motion(x, y, u[None], v[None], valid, R_true[None], F)
    moved = reexpress(measured, R_true[None], R_other[None], F, (360, 640))
    assert np.abs((moved - direct)[:, :2]).max() * F < 0.05


def test_a_rotation_that_explains_little_of_the_frame_gives_no_zoom_or_roll():
    """cockatoo: a bird's face, close to the lens, won some pairs' vote, and its
    approach read as the camera's zoom. Where the rotation explains under 40% of the
    frame's vectors, only the translation counts: the camera's zoom here is none."""
    x, y = _grid()
    R_bird = so3.exp_so3(np.array([0.0, 1.5 * GATE_PX / F, 0.0]))
    bird = np.hypot(x / 300, y / 170) < 0.6
    assert 0.2 < bird.mean() < 0.4
    u, v = _flow(x, y, np.eye(3), (0.0, 0.0))  # the room: still, 1.5 gates off the bird
    u_bird, v_bird = _flow(x, y, R_bird, (0.0, 0.0), scale=0.01)  # it comes 1% closer
    u[bird], v[bird] = u_bird[bird], v_bird[bird]
    valid = np.ones((1, len(x)), bool)
    residual = residual_motion(x, y, u[None], v[None], valid, R_bird[None], F)[0]
    assert residual[2] == 0.0 and residual[3] == 0.0
    # Fitted on the bird alone, the zoom is the bird's:
    alone = residual_motion(x, y, u[None], v[None], bird[None], R_bird[None], F)[0]
    assert alone[2] == pytest.approx(0.01, abs=1e-3)
