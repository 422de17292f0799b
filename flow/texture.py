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
from numba import njit
from numpy.typing import NDArray

from flow.base import to_grey

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
    same filters called from numpy; 1.6–1.9 ms on a slower day, when
    :func:`min_eigenvalue_at` took 0.19 at the sample grid's points), with the gradient
    divided by 4·WINDOW·255 and the window summed, not averaged; the factor undoes both.
    """
    grey = np.ascontiguousarray(to_grey(frame), np.uint8)
    lam = cv2.cornerMinEigenVal(grey, WINDOW, ksize=3)
    return lam * np.float32(OPENCV_SCALE)


def min_eigenvalue_at(frame: NDArray, rows: NDArray, cols: NDArray) -> NDArray[np.float32]:
    """λ_min at the points ``rows`` × ``cols`` (len(rows), len(cols)) alone: what
    :func:`min_eigenvalue` gives there, within float32's last bit.

    Pass 1 reads the flow at 576 points of a 480×270 frame, so only their windows are
    summed (the gradients are OpenCV's, the sums in float64 as its box filter makes
    them, which slides them along the rows: 2 of 34,560 points of a 1080p clip's 60
    frames came out one bit apart, none near the threshold): 0.19 ms a frame against
    1.85 for the whole map, on the thread that computes the flow.
    """
    grey = np.ascontiguousarray(to_grey(frame), np.uint8)
    scale = 1.0 / (4 * WINDOW * 255)  # cornerMinEigenVal's, undone by OPENCV_SCALE
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3, scale=scale)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3, scale=scale)
    sums = _window_sums(gx, gy, np.asarray(rows, np.int64), np.asarray(cols, np.int64), WINDOW)
    a, b, c = sums[..., 0] * np.float32(0.5), sums[..., 1], sums[..., 2] * np.float32(0.5)
    return ((a + c) - np.sqrt((a - c) ** 2 + b * b)) * np.float32(OPENCV_SCALE)


@njit(cache=True)
def _window_sums(gx, gy, rows, cols, window) -> np.ndarray:
    """Σ gx², Σ gx·gy, Σ gy² (float32 products, summed in float64) over the window
    around each point, the border reflected as OpenCV's default (…cb|abc…)."""
    h = window // 2
    height, width = gx.shape
    out = np.empty((rows.shape[0], cols.shape[0], 3), np.float32)
    for i in range(rows.shape[0]):
        for j in range(cols.shape[0]):
            a = b = c = 0.0
            for dy in range(-h, h + 1):
                y = _reflect(rows[i] + dy, height)
                for dx in range(-h, h + 1):
                    x = _reflect(cols[j] + dx, width)
                    p, q = gx[y, x], gy[y, x]
                    a += p * p
                    b += p * q
                    c += q * q
            out[i, j, 0], out[i, j, 1], out[i, j, 2] = a, b, c
    return out


@njit(cache=True, inline="always")
def _reflect(k: int, n: int) -> int:
    """Index k of an axis of length n, reflected about its ends without repeating them."""
    if n == 1:
        return 0
    while k < 0 or k >= n:
        k = -k if k < 0 else 2 * (n - 1) - k
    return k


def textured(
    frame: NDArray, rows: NDArray, cols: NDArray, threshold: float = MIN_TEXTURE
) -> NDArray[np.bool_]:
    """Whether the flow at each of the points ``rows`` × ``cols`` of ``frame`` can be
    measured (λ_min ≥ ``threshold``), flattened row by row (len(rows)·len(cols),).

    >>> flat = np.full((32, 32), 128, np.uint8)
    >>> bool(textured(flat, np.array([16]), np.array([16]))[0])
    False
    """
    return (min_eigenvalue_at(np.asarray(frame), rows, cols) >= threshold).ravel()
