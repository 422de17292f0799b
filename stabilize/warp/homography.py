"""Correction homographies: the pinhole camera turned by the correction, then zoomed.

For raw orientation O_t and smoothed S_t, the correction C_t = S_t O_tᵀ turns frame t's
rays into the smoothed camera's. Output pixels are then

    p_out ~ K' C_t K⁻¹ p_in,      K' = K with the focal length times the zoom z

(about the principal point).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def zoomed(K: NDArray, zoom: float | NDArray) -> NDArray:
    """K with the focal length times the zoom (a stack of them for an array of zooms)."""
    zoom = np.asarray(zoom, dtype=np.float64)
    out = np.broadcast_to(np.asarray(K, dtype=np.float64), (*zoom.shape, 3, 3)).copy()
    out[..., 0, 0] *= zoom
    out[..., 1, 1] *= zoom
    return out


def homography(K: NDArray, C: NDArray, zoom: float = 1.0) -> NDArray[np.float64]:
    """Input pixels → output pixels: K' C K⁻¹ (for one C, or a stack of them)."""
    H = zoomed(K, zoom) @ C @ np.linalg.inv(K)
    return H / H[..., 2:, 2:]


def inverses(H: NDArray) -> NDArray[np.float64]:
    """Inverse homographies, scaled to H[2, 2] = 1 so that they interpolate."""
    Hinv = np.linalg.inv(H)
    return Hinv / Hinv[..., 2:, 2:]
