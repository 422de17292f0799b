"""Rotation-vector and matrix helpers on SO(3), vectorised over leading axes.

A rotation vector ``w`` is axis times angle in radians; ``exp(w)`` is the matrix
that turns vectors by that angle about that axis (right-handed).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def hat(w: ArrayLike) -> NDArray[np.float64]:
    """Skew matrix [w]x with [w]x v = w × v, for (..., 3) vectors."""
    w = np.asarray(w, dtype=np.float64)
    out = np.zeros((*w.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -w[..., 2], w[..., 1]
    out[..., 1, 0], out[..., 1, 2] = w[..., 2], -w[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -w[..., 1], w[..., 0]
    return out


def exp_so3(w: ArrayLike) -> NDArray[np.float64]:
    """Rodrigues: R = I + sin(θ)/θ [w]x + (1 - cos θ)/θ² [w]x², θ = |w|.

    Uses the Taylor series below θ = 1e-4 so tiny rotations stay exact to float64.
    """
    w = np.asarray(w, dtype=np.float64)
    theta2 = np.sum(w * w, axis=-1)[..., None, None]
    theta = np.sqrt(theta2)
    small = theta < 1e-4
    safe = np.where(small, 1.0, theta)
    a = np.where(small, 1.0 - theta2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta2 / 24.0, (1.0 - np.cos(safe)) / (safe * safe))
    k = hat(w)
    return np.eye(3) + a * k + b * (k @ k)


def log_so3(R: ArrayLike) -> NDArray[np.float64]:
    """Rotation vector of R (inverse of :func:`exp_so3`), valid for angles up to π."""
    R = np.asarray(R, dtype=np.float64)
    # The quaternion route is well conditioned at every angle, unlike acos of the trace.
    from scipy.spatial.transform import Rotation

    flat = R.reshape(-1, 3, 3)
    return Rotation.from_matrix(flat).as_rotvec().reshape(*R.shape[:-2], 3)


def angle(R: ArrayLike) -> NDArray[np.float64]:
    """Rotation angle θ(R) in radians, computed stably for small angles."""
    R = np.asarray(R, dtype=np.float64)
    skew = np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]],
        axis=-1,
    )
    sin_theta = 0.5 * np.linalg.norm(skew, axis=-1)
    cos_theta = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    return np.arctan2(sin_theta, cos_theta)


def angular_error_deg(R_hat: ArrayLike, R: ArrayLike) -> NDArray[np.float64]:
    """θ(R̂ Rᵀ) in degrees: the error measure of CONVENTIONS.md and the paper's AAE."""
    R_hat = np.asarray(R_hat, dtype=np.float64)
    R = np.asarray(R, dtype=np.float64)
    return np.degrees(angle(R_hat @ np.swapaxes(R, -1, -2)))


def random_rotations(
    rng: np.random.Generator, n: int, max_deg: float, min_deg: float = 0.0
) -> NDArray[np.float64]:
    """n rotation matrices with uniform random axes and angles uniform in [min_deg, max_deg]."""
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.radians(rng.uniform(min_deg, max_deg, size=(n, 1)))
    return exp_so3(axes * angles)
