"""Correction homographies, the zoom that hides every border, and the warp itself.

For raw orientation O_t and smoothed S_t, the correction C_t = S_t O_tᵀ turns frame t's
rays into the smoothed camera's. Output pixels are then

    p_out ~ K' C_t K⁻¹ p_in,      K' = K with the focal length times the zoom z

(about the principal point). A zoom z hides the borders of frame t when every output
border pixel maps back inside the input frame.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

BORDER_SAMPLES = 16  # points per edge checked for coverage


def zoomed(K: NDArray, zoom: float) -> NDArray:
    out = np.array(K, dtype=np.float64, copy=True)
    out[0, 0] *= zoom
    out[1, 1] *= zoom
    return out


def homography(K: NDArray, C: NDArray, zoom: float = 1.0) -> NDArray[np.float64]:
    """Input pixels → output pixels: K' C K⁻¹."""
    H = zoomed(K, zoom) @ C @ np.linalg.inv(K)
    return H / H[2, 2]


def _border(size: tuple[int, int]) -> NDArray:
    h, w = size
    xs = np.linspace(-0.5, w - 0.5, BORDER_SAMPLES)
    ys = np.linspace(-0.5, h - 0.5, BORDER_SAMPLES)
    return np.concatenate(
        [
            np.stack([xs, np.full_like(xs, -0.5)], 1),
            np.stack([xs, np.full_like(xs, h - 0.5)], 1),
            np.stack([np.full_like(ys, -0.5), ys], 1),
            np.stack([np.full_like(ys, w - 0.5), ys], 1),
        ]
    )


def covers(K: NDArray, C: NDArray, zoom: float, size: tuple[int, int]) -> bool:
    """Whether the output frame at ``zoom`` lies entirely inside the warped input."""
    h, w = size
    Hinv = np.linalg.inv(homography(K, C, zoom))
    pts = np.c_[_border(size), np.ones(4 * BORDER_SAMPLES)] @ Hinv.T
    if np.any(pts[:, 2] <= 0):
        return False
    x, y = pts[:, 0] / pts[:, 2], pts[:, 1] / pts[:, 2]
    return bool(np.all((x >= -0.5) & (x <= w - 0.5) & (y >= -0.5) & (y <= h - 0.5)))


def required_zoom(K: NDArray, C: NDArray, size: tuple[int, int], max_zoom: float = 4.0) -> float:
    """The smallest zoom ≥ 1 with no border in frame (bisection); inf if above max_zoom."""
    if covers(K, C, 1.0, size):
        return 1.0
    if not covers(K, C, max_zoom, size):
        return np.inf
    lo, hi = 1.0, max_zoom
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if covers(K, C, mid, size) else (mid, hi)
    return hi


def warp_frame(frame: NDArray[np.uint8], H: NDArray) -> NDArray[np.uint8]:
    """cv2.warpPerspective (about 10 ms per 1080p frame on this CPU), black outside."""
    h, w = frame.shape[:2]
    return cv2.warpPerspective(
        frame, H, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT
    )
