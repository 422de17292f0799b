"""Repairing the frames whose rotation too few flow vectors agreed on.

A close moving subject can fill the frame and win the vote with a handful of vectors;
one such frame is a jump in the path that the smoothing then has to zoom around. Its
rotation is replaced by the mean rotation vector of the reliable frames within
``REPAIR_WINDOW`` (or the nearest reliable one).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rotation import so3

MIN_SUPPORT = 0.03  # below this share of agreeing vectors a frame's rotation is a guess
RELATIVE_SUPPORT = 0.35  # ...or below this fraction of the clip's median support
REPAIR_WINDOW = 3  # frames on each side whose rotations stand in for an unreliable one


def repair_unreliable(R: NDArray, support: NDArray) -> tuple[NDArray, NDArray]:
    """Replace the rotations R (N-1, 3, 3) whose ``support`` is too low.

    Returns (R, reliable mask); all frames count as reliable when none, or all, are.
    """
    support = np.asarray(support)
    reliable = support >= max(MIN_SUPPORT, RELATIVE_SUPPORT * float(np.median(support)))
    if reliable.all() or not reliable.any():
        return R, np.ones(len(R), bool)
    rotvecs = so3.log_so3(R)
    good = np.flatnonzero(reliable)
    out = rotvecs.copy()
    for k in np.flatnonzero(~reliable):
        near = good[np.abs(good - k) <= REPAIR_WINDOW]
        if near.size == 0:
            near = good[[np.argmin(np.abs(good - k))]]
        out[k] = rotvecs[near].mean(axis=0)
    return so3.exp_so3(out), reliable
