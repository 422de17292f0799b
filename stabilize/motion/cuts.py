"""Cuts: where an edited clip changes from one shot to another.

No camera turns across a cut, yet the vote reads some rotation there: the flow between
two unrelated pictures agrees on little (a hero7 shot cut to a karma one: 1.4% of its
vectors, against 11% on either side), and what it reads is a jump (about 2° there) that
the smoothed path then spreads over a second on each side, a drift the viewer sees. Such
a pair's turn is taken from its neighbours' instead (:func:`stabilize.motion.repair`).

A pair is a cut where its two frames look alike nowhere and the flow agrees on nearly
nothing. Looking alike is the best normalised cross-correlation of the frames' blurred
grey thumbnails, each one's middle shifted over the other by up to 16% of its width and
height each way: a turn moves the picture, it does not replace it. On every pair of the
real clips here (cockatoo's bird covering the lens and its exposure jumps, hero7's walk,
the drones, phone-cc9's drive, the rendered sample) it read at least 0.86; across 360
cuts between those clips a median 0.31, at most 0.69, and 90% under ``LIKENESS``: a cut
between two pictures alike enough is left as it was. (Colour histograms could not tell
them apart: cockatoo's exposure jumps read a Bhattacharyya distance of 0.44 against a
cut's 0.65.) Thumbnails 96 px wide separate as 128 px ones do, and cost 0.2 ms a pair.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.motion.repair import MIN_SUPPORT

THUMBNAIL_WIDTH = 96  # px: the thumbnails compared
BLUR_PX = 0.75  # Gaussian σ of the thumbnails, px: noise and compression blocks do not count
SHIFT = 0.16  # of each thumbnail's width and height, each way, its middle shifts over the other
LIKENESS = 0.6  # the correlation under which two frames look alike nowhere


def thumbnail(frame: NDArray) -> NDArray[np.float32]:
    """A frame (RGB or grey) as a blurred grey thumbnail ``THUMBNAIL_WIDTH`` px wide."""
    grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY) if frame.ndim == 3 else frame
    h, w = grey.shape
    size = (THUMBNAIL_WIDTH, max(round(h * THUMBNAIL_WIDTH / w), 8))
    small = cv2.resize(grey, size, interpolation=cv2.INTER_AREA).astype(np.float32)
    return cv2.GaussianBlur(small, (0, 0), BLUR_PX)


def likeness(a: NDArray[np.float32], b: NDArray[np.float32]) -> float:
    """How alike two thumbnails look: the best normalised cross-correlation of either's
    middle over the other, shifted by up to ``SHIFT`` each way (1: the same picture, moved).

    >>> rng = np.random.default_rng(0)
    >>> picture = cv2.GaussianBlur(rng.random((72, 160), np.float32), (0, 0), 2.0)
    >>> round(likeness(picture[:, :96], picture[:, 10:106]), 3)  # turned 10 px
    1.0
    >>> likeness(picture[:, :96], rng.random((72, 96), np.float32)) < LIKENESS
    True
    """
    h, w = a.shape
    dy, dx = round(h * SHIFT), round(w * SHIFT)
    best = -1.0
    for one, other in ((a, b), (b, a)):
        middle = one[dy : h - dy, dx : w - dx]
        if middle.std() > 1e-6:  # a flat picture matches nothing
            best = max(best, float(cv2.matchTemplate(other, middle, cv2.TM_CCOEFF_NORMED).max()))
    return best


def cut_pairs(likenesses: NDArray, support: NDArray) -> NDArray[np.bool_]:
    """Which frame pairs are cuts: their frames look alike nowhere (``likenesses`` under
    ``LIKENESS``) and under ``MIN_SUPPORT`` of the flow agrees on any rotation."""
    return (np.asarray(likenesses) < LIKENESS) & (np.asarray(support) < MIN_SUPPORT)
