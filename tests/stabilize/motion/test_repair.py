"""Repairing the frames too few flow vectors agreed on."""

import numpy as np

from rotation import so3
from stabilize.motion.repair import repair_unreliable


def test_unreliable_frames_are_repaired_from_their_neighbours():
    rv = np.tile([0.01, 0.0, 0.0], (9, 1))
    rv[4] = [0.0, 0.08, 0.0]  # a spike that few vectors voted for
    support = np.full(9, 0.2)
    support[4] = 0.01
    R, reliable = repair_unreliable(so3.exp_so3(rv), support)
    assert not reliable[4] and reliable.sum() == 8
    np.testing.assert_allclose(so3.log_so3(R[4]), [0.01, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(so3.log_so3(R[0]), rv[0], atol=1e-12)
