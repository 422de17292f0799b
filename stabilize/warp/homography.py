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


def cropping_ratio(H: NDArray, size: tuple[int, int]) -> NDArray[np.float64]:
    """The cropping ratio of each frame (N,) warped by H (N, 3, 3), input → output pixels,
    at an output of ``size`` (height, width): the scale √|det J| of the inverse map at
    the output's middle c, where for H⁻¹ = [[A, t], [bᵀ, s]] and its image x of c

        J = (A − x bᵀ) / (bᵀc + s),

    the share of the input's width the output shows there. It is what an evaluation of
    the output against its input reads as cropping (1: nothing cropped; 1/z for a zoom
    z). Unlike the zoom the crop mode chose, it counts a 2-D correction's zoom-outs.

    >>> import numpy as np
    >>> zoom = np.array([[[1.25, 0, -80.0], [0, 1.25, -45.0], [0, 0, 1]]])
    >>> cropping_ratio(zoom, (360, 640)).round(6).tolist()
    [0.8]
    """
    Hinv = np.linalg.inv(np.asarray(H, np.float64))
    h, w = size
    c = np.array([(w - 1) / 2, (h - 1) / 2, 1.0])
    u = Hinv @ c
    x = u[..., :2] / u[..., 2:]
    J = (Hinv[..., :2, :2] - x[..., :, None] * Hinv[..., 2, None, :2]) / u[..., 2, None, None]
    return np.sqrt(np.abs(np.linalg.det(J)))
