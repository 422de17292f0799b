"""Pinhole intrinsics, following CONVENTIONS.md.

Pixel centres sit at integer coordinates, so the default principal point is
((W-1)/2, (H-1)/2), and resizing by s maps f → s f and c + 0.5 → s (c + 0.5).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray


def default_center(size: tuple[int, int]) -> tuple[float, float]:
    """Principal point (cx, cy) of an (H, W) image with no other calibration."""
    h, w = size
    return ((w - 1) / 2.0, (h - 1) / 2.0)


def intrinsics(
    focal: float, size: tuple[int, int], center: tuple[float, float] | None = None
) -> NDArray[np.float64]:
    """K = [[f, 0, cx], [0, f, cy], [0, 0, 1]] for an (H, W) image."""
    cx, cy = default_center(size) if center is None else center
    return np.array([[focal, 0.0, cx], [0.0, focal, cy], [0.0, 0.0, 1.0]])


def scale_intrinsics(K: NDArray[np.float64], sx: float, sy: float | None = None) -> NDArray:
    """K of the same camera after resizing the image by (sx, sy).

    fx' = sx fx and cx' + 0.5 = sx (cx + 0.5), likewise in y.
    """
    sy = sx if sy is None else sy
    out = np.array(K, dtype=np.float64, copy=True)
    out[0, 0] *= sx
    out[1, 1] *= sy
    out[0, 2] = sx * (K[0, 2] + 0.5) - 0.5
    out[1, 2] = sy * (K[1, 2] + 0.5) - 0.5
    return out


def focal_from_fov(fov_deg: float, width: int) -> float:
    """Focal length in pixels for a horizontal field of view across ``width`` pixels."""
    return 0.5 * width / math.tan(math.radians(fov_deg) / 2.0)


def fov_from_focal(focal: float, width: int) -> float:
    """Horizontal field of view in degrees of a focal length in pixels."""
    return math.degrees(2.0 * math.atan(0.5 * width / focal))
