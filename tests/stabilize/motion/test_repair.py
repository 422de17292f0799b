"""Repairing the frames too few flow vectors agreed on, and that jump."""

import numpy as np

from rotation import so3
from stabilize.motion.repair import repair_unreliable


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
