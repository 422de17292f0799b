"""Repairing the frames too few flow vectors agreed on, and that jump."""

from dataclasses import replace
from functools import partial

import numpy as np

from rotation import so3
from stabilize.motion.repair import MIN_AGREEING, repair_unreliable
from stabilize.motion.residual import landing
from stabilize.motion.track import Samples


def test_a_jump_few_vectors_voted_for_is_repaired_from_its_neighbours():
    rv = np.tile([0.01, 0.0, 0.0], (9, 1))
    rv[4] = [0.0, 0.08, 0.0]  # a spike that few vectors voted for
    support = np.full(9, 0.2)
    support[4] = 0.01
    R, reliable = repair_unreliable(so3.exp_so3(rv), support)
    assert not reliable[4] and reliable.sum() == 8
    np.testing.assert_allclose(so3.log_so3(R[4]), [0.01, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(so3.log_so3(R[0]), rv[0], atol=1e-12)


def test_a_low_support_frame_that_follows_a_fast_shake_is_kept():
    # a shake that turns ±0.6° from frame to frame: the low-support frame is on it
    rng = np.random.default_rng(3)
    rv = np.c_[0.01 * rng.standard_normal(9), 0.01 * rng.standard_normal(9), np.zeros(9)]
    support = np.full(9, 0.5)
    support[4] = 0.12  # a quarter of the median: blur, near walls
    R, reliable = repair_unreliable(so3.exp_so3(rv), support)
    assert reliable.all()
    np.testing.assert_allclose(so3.log_so3(R), rv, atol=1e-12)


F = 400.0  # px, the flow's focal length (scale 1)


def grid_samples(rotations: np.ndarray, subject: np.ndarray | None = None) -> Samples:
    """Samples of a 24×24 grid whose static points move as ``rotations`` (n, 3, 3) turn
    them; where ``subject`` (n, 3, 3) is given, the grid's left 40% moves by it instead."""
    gx, gy = np.meshgrid(np.linspace(-300, 300, 24), np.linspace(-170, 170, 24))
    x, y = gx.ravel(), gy.ravel()
    lx, ly = landing(x, y, rotations, F)
    u, v = F * lx - x, F * ly - y
    if subject is not None:
        sx, sy = landing(x, y, subject, F)
        left = x < np.quantile(x, 0.4)
        u[:, left], v[:, left] = (F * sx - x)[:, left], (F * sy - y)[:, left]
    valid = np.ones(u.shape, bool)
    return Samples(u.astype(np.float32), v.astype(np.float32), valid, x, y, gy.ravel(), 340)


def spiked(spike_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Rotation vectors of a steady pan with pair 4 turned ``spike_deg`` about y, and
    supports with pair 4's low."""
    rv = np.tile([0.002, 0.0, 0.0], (9, 1))
    rv[4] = [0.0, np.radians(spike_deg), 0.0]
    support = np.full(9, 0.3)
    support[4] = 0.02
    return rv, support


def test_a_jolt_the_flow_follows_is_kept():
    rv, support = spiked(3.0)
    R = so3.exp_so3(rv)
    samples = grid_samples(R)  # the whole scene turned with the jolt
    kept, reliable = repair_unreliable(R, support, partial(samples.agreeing, focal=F))
    assert reliable.all()
    np.testing.assert_allclose(so3.log_so3(kept), rv, atol=1e-12)
    # without the flow, the same jump is repaired
    _, blind = repair_unreliable(R, support)
    assert not blind[4]


def test_a_subject_that_won_the_vote_is_repaired_though_the_flow_is_at_hand():
    rv, support = spiked(3.0)
    steady = rv.copy()
    steady[4] = rv[3]
    # the scene turned with its neighbours; a subject over 40% of the frame swept 3°
    samples = grid_samples(so3.exp_so3(steady), subject=so3.exp_so3(rv))
    R, reliable = repair_unreliable(so3.exp_so3(rv), support, partial(samples.agreeing, focal=F))
    assert not reliable[4]
    np.testing.assert_allclose(so3.log_so3(R[4]), rv[3], atol=1e-12)


def test_a_jump_too_few_vectors_follow_is_repaired():
    rv, support = spiked(3.0)
    R = so3.exp_so3(rv)
    samples = grid_samples(R)
    few = np.zeros_like(samples.valid)
    few[:, : MIN_AGREEING - 1] = True  # the rest of the frame blurred or covered
    sparse = replace(samples, valid=few)
    _, reliable = repair_unreliable(R, support, partial(sparse.agreeing, focal=F))
    assert not reliable[4]


def test_the_repair_keeps_the_shake_the_scene_shows_in_a_frame_a_subject_won():
    # the scene shakes 0.3° off its neighbours in pair 4, and a subject over 40% of the
    # frame swept 3°, winning the vote: the repair is the scene's own rotation, shake
    # and all, not the neighbours' mean
    rv, support = spiked(3.0)
    scene = rv.copy()
    scene[4] = rv[3] + [0.0, np.radians(0.3), 0.0]
    samples = grid_samples(so3.exp_so3(scene), subject=so3.exp_so3(rv))
    agreeing, refined = partial(samples.agreeing, focal=F), partial(samples.refined, focal=F)
    R, reliable = repair_unreliable(so3.exp_so3(rv), support, agreeing, refined)
    assert not reliable[4]
    assert np.degrees(np.linalg.norm(so3.log_so3(R[4:5])[0] - scene[4])) < 0.01
    R_mean, _ = repair_unreliable(so3.exp_so3(rv), support, agreeing)
    assert np.degrees(np.linalg.norm(so3.log_so3(R_mean[4:5])[0] - scene[4])) > 0.25


def test_a_jolt_the_flow_settles_on_from_the_neighbours_is_kept():
    # a pan that speeds up 0.2° a frame at the clip's end, with little support there
    rv = np.c_[np.zeros(9), np.radians(np.r_[np.full(6, 0.6), 0.8, 1.0, 1.2]), np.zeros(9)]
    support = np.r_[np.full(6, 0.6), 0.15, 0.15, 0.15]
    R = so3.exp_so3(rv)
    samples = grid_samples(R)
    agreeing, refined = partial(samples.agreeing, focal=F), partial(samples.refined, focal=F)
    kept, reliable = repair_unreliable(R, support, agreeing, refined)
    assert reliable.all()
    np.testing.assert_allclose(so3.log_so3(kept), rv, atol=1e-12)
