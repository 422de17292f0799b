"""Wobble: what a rolling shutter adds to the frame-to-frame motion, in pixels.

A rolling shutter skews each frame by the camera's turn during its readout: a yaw
shears the columns (x moves with y), a pitch stretches or squeezes the rows. As the turn
changes from frame to frame, consecutive frames differ by a shear and a stretch, which
the viewer sees as jello. Consecutive frames are registered by a homography (the ORB
registration of :mod:`stabilize.evaluate.metrics`, refined to a fraction of a pixel); of
its linear part at the frame's centre, J = [[a, b], [c, d]], the part no similarity has,

    ε = ((a - d) / 2, (b + c) / 2),

is the stretch along the axes and the shear. The wobble is the RMS length of ε over the
pairs, times w/2: the px it moves the frame's side by, at the clip's width w. A
global-shutter camera's turn is a homography whose linear part at the centre is a
similarity to second order in the angle (0.05 px for a 1° turn at 960 px), so it scores
about 0; a homography rather than an affine fit, so that the turn's perspective terms are
not taken for stretch. Lower is better.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def non_similar_part(J: NDArray) -> NDArray[np.float64]:
    """ε (2,) of a 2×2 linear map J: its stretch along the axes and its shear."""
    (a, b), (c, d) = np.asarray(J, dtype=np.float64)
    return np.array([(a - d) / 2.0, (b + c) / 2.0])


def wobble(parts: NDArray, width: int) -> float:
    """The wobble (px) of the non-similar parts (N, 2) of a clip ``width`` px wide."""
    parts = np.asarray(parts, dtype=np.float64).reshape(-1, 2)
    if not len(parts):
        return float("nan")
    return float(np.sqrt(np.mean(np.sum(parts**2, axis=1))) * width / 2)
