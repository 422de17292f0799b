"""Where a flow vector is measured rather than filled in: the image's texture.

A flow backend can only measure motion where the image has structure in two
directions. On a flat wall, a clear sky or a blurred feather, and along a straight edge
(the aperture problem), DIS and RAFT fill the field in from the neighbourhood, and what
they fill in is a guess: a bird's smooth plumage next to the wall reads the bird's
motion, a dashboard's flat top reads no motion at all. Such vectors vote in the rotation
estimator like any other.

The measure is the smaller eigenvalue of the structure tensor (Shi and Tomasi, "Good
features to track", CVPR 1994),

    λ_min = ½ (a + c − √((a − c)² + 4b²)),   [a b; b c] = mean_w [gx² gx·gy; gx·gy gy²],

with the gradients g in grey levels per pixel (Sobel / 8) averaged over a ``WINDOW`` px
box: the squared gradient, in the window's weakest direction. A vector is measured where
λ_min ≥ ``MIN_TEXTURE``.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

WINDOW = 7  # px at the flow's size: about DIS's patch
# (grey levels / px)²: a flat patch's sensor and codec noise reads 0.05–0.3 on the real
# clips (their 10th percentile), an edge's weak direction about as little. At 1, the
# weakest direction still changes by about 7 grey levels across the window. Leaving out
# what lies below raised the rotation's agreement with phone-cc9's gyro from 0.090° to
# 0.057° AAE (0.5 and 1.5 read 0.055° and 0.053°); karma, a drone over textured ground,
# went 0.019° → 0.022°
MIN_TEXTURE = 1.0
# cornerMinEigenVal's λ (Sobel / (4·WINDOW·255), summed over the window) → (grey / px)²
OPENCV_SCALE = (4 * WINDOW * 255) ** 2 / (WINDOW**2 * 8**2)


def min_eigenvalue(frame: NDArray) -> NDArray[np.float32]:
    """λ_min of the structure tensor (H, W) of an RGB (H, W, 3) or grey (H, W) uint8
    frame, in (grey levels / px)².

    OpenCV's ``cornerMinEigenVal`` computes it (0.8 ms at 480×270, against 2 ms for the
    same filters called from numpy), with the gradient divided by 4·WINDOW·255 and the
    window summed, not averaged; the factor undoes both.
    """
    grey = frame if frame.ndim == 2 else cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)
    lam = cv2.cornerMinEigenVal(np.ascontiguousarray(grey, np.uint8), WINDOW, ksize=3)
    return lam * np.float32(OPENCV_SCALE)


def textured(
    frame: NDArray, rows: NDArray, cols: NDArray, threshold: float = MIN_TEXTURE
) -> NDArray[np.bool_]:
    """Whether the flow at each of the points ``rows`` × ``cols`` of ``frame`` can be
    measured (λ_min ≥ ``threshold``), flattened row by row (len(rows)·len(cols),).

    >>> flat = np.full((32, 32), 128, np.uint8)
    >>> bool(textured(flat, np.array([16]), np.array([16]))[0])
    False
    """
    lam = min_eigenvalue(np.asarray(frame))
    return (lam[np.asarray(rows)[:, None], np.asarray(cols)[None, :]] >= threshold).ravel()
