"""Sub-bin refinement: fit R to the vote's inliers with the exact rotation homography.

For a pixel p = (x, y) (relative to the principal point) and its flow target q, the
model is q̂(R) = π(R (x, y, f)), with π(X) = f (X₀/X₂, X₁/X₂). Perturbing on the left,
R ← exp([δ]×) R, gives X ← X + δ × X, so the Jacobian of q̂ with respect to δ is

    J = f / X₂ · [[1, 0, -X₀/X₂], [0, 1, -X₁/X₂]] · (-[X]×).

Gauss-Newton solves (Σ wᵢ JᵢᵀJᵢ) δ = -Σ wᵢ Jᵢᵀ eᵢ with eᵢ = q̂ᵢ - qᵢ.

The fit is robust (Tukey's biweight), starts from the winning bin, and lets the
residuals of the flow itself, not the bin size, set the final accuracy.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

RAYLEIGH_MEDIAN = math.sqrt(2.0 * math.log(2.0))  # median of |e| / σ for 2-D Gaussian e
RAYLEIGH_K = 3.0  # Tukey scale in units of σ̂
MIN_SCALE_PX = 0.1  # noise-free flow must not shrink the scale to nothing


@njit(cache=True)
def rodrigues(w: np.ndarray) -> np.ndarray:
    """exp([w]×) for one rotation vector, by Rodrigues' formula (the kernels' own copy of
    :func:`rotation.so3.exp_so3`, which works on stacks in numpy)."""
    theta = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    k = np.zeros((3, 3))
    k[0, 1], k[0, 2], k[1, 0] = -w[2], w[1], w[2]
    k[1, 2], k[2, 0], k[2, 1] = -w[0], -w[1], w[0]
    if theta < 1e-4:
        a = 1.0 - theta * theta / 6.0
        b = 0.5 - theta * theta / 24.0
    else:
        a = math.sin(theta) / theta
        b = (1.0 - math.cos(theta)) / (theta * theta)
    return np.eye(3) + a * k + b * (k @ k)


@njit(cache=True, inline="always")
def rotate_ray(R: np.ndarray, x: float, y: float, f: float) -> tuple:
    """R (x, y, f): the ray of pixel (x, y) (relative to the principal point) turned by R."""
    X0 = R[0, 0] * x + R[0, 1] * y + R[0, 2] * f
    X1 = R[1, 0] * x + R[1, 1] * y + R[1, 2] * f
    X2 = R[2, 0] * x + R[2, 1] * y + R[2, 2] * f
    return X0, X1, X2


@njit(cache=True)
def residuals(x, y, qx, qy, f, R, valid) -> np.ndarray:
    """|q̂ᵢ - qᵢ| in pixels for each vector (inf where invalid or behind the camera)."""
    out = np.full(x.shape[0], np.inf)
    for i in range(x.shape[0]):
        if not valid[i]:
            continue
        X0, X1, X2 = rotate_ray(R, x[i], y[i], f)
        if X2 > 1e-9:
            out[i] = math.hypot(f * X0 / X2 - qx[i], f * X1 / X2 - qy[i])
    return out


@njit(cache=True)
def gauss_newton_step(x, y, qx, qy, f, R, w) -> np.ndarray:
    """One weighted Gauss-Newton update δ (left perturbation), zero if ill-posed."""
    H = np.zeros((3, 3))
    g = np.zeros(3)
    J = np.empty((2, 3))
    for i in range(x.shape[0]):
        if w[i] <= 0.0:
            continue
        X0, X1, X2 = rotate_ray(R, x[i], y[i], f)
        if X2 <= 1e-9:
            continue
        iz = 1.0 / X2
        ex = f * X0 * iz - qx[i]
        ey = f * X1 * iz - qy[i]
        # d(δ × X)/dδ = -[X]×; chain with the projection derivative.
        a0, a2 = f * iz, -f * X0 * iz * iz
        b1, b2 = f * iz, -f * X1 * iz * iz
        # rows of -[X]×: (0, X2, -X1), (-X2, 0, X0), (X1, -X0, 0)
        J[0, 0] = a2 * X1
        J[0, 1] = a0 * X2 - a2 * X0
        J[0, 2] = -a0 * X1
        J[1, 0] = -b1 * X2 + b2 * X1
        J[1, 1] = -b2 * X0
        J[1, 2] = b1 * X0
        for r in range(3):
            g[r] += w[i] * (J[0, r] * ex + J[1, r] * ey)
            for c in range(3):
                H[r, c] += w[i] * (J[0, r] * J[0, c] + J[1, r] * J[1, c])
    return -solve3(H, g)


@njit(cache=True)
def solve3(H: np.ndarray, g: np.ndarray) -> np.ndarray:
    """H⁻¹ g for a 3×3 H by its adjugate, H⁻¹ = adj(H) / det(H); zero where |det H| <
    1e-30 (ill-posed). Written out rather than ``np.linalg.solve``, whose LAPACK binding
    took 4.1 s of a fresh install's first compile, then 20 s, for a 3×3 system."""
    c00 = H[1, 1] * H[2, 2] - H[1, 2] * H[2, 1]
    c01 = H[1, 2] * H[2, 0] - H[1, 0] * H[2, 2]
    c02 = H[1, 0] * H[2, 1] - H[1, 1] * H[2, 0]
    det = H[0, 0] * c00 + H[0, 1] * c01 + H[0, 2] * c02
    out = np.zeros(3)
    if abs(det) < 1e-30:
        return out
    c10 = H[0, 2] * H[2, 1] - H[0, 1] * H[2, 2]
    c11 = H[0, 0] * H[2, 2] - H[0, 2] * H[2, 0]
    c12 = H[0, 1] * H[2, 0] - H[0, 0] * H[2, 1]
    c20 = H[0, 1] * H[1, 2] - H[0, 2] * H[1, 1]
    c21 = H[0, 2] * H[1, 0] - H[0, 0] * H[1, 2]
    c22 = H[0, 0] * H[1, 1] - H[0, 1] * H[1, 0]
    out[0] = (c00 * g[0] + c10 * g[1] + c20 * g[2]) / det
    out[1] = (c01 * g[0] + c11 * g[1] + c21 * g[2]) / det
    out[2] = (c02 * g[0] + c12 * g[1] + c22 * g[2]) / det
    return out


@njit(cache=True)
def fit(x, y, qx, qy, f, R, w, iters: int) -> np.ndarray:
    """Gauss-Newton with fixed weights."""
    for _ in range(iters):
        delta = gauss_newton_step(x, y, qx, qy, f, R, w)
        R = rodrigues(delta) @ R
        if math.sqrt(delta @ delta) < 1e-12:
            break
    return R


@njit(cache=True)
def refine(x, y, qx, qy, f, R, valid, gate_px: float, iters: int = 6) -> np.ndarray:
    """Iteratively reweighted Gauss-Newton around the winning bin's rotation R.

    Weights are Tukey's biweight of the residual. The first scale is ``gate_px``
    (a few bins' worth of pixels, so every vector whose line passes near the
    winning bin takes part, not only those through it: selecting by the bin alone
    would pull the fit towards the bin's centre). After that the scale is
    ``RAYLEIGH_K`` σ̂, with σ̂ from the median of the weighted residuals, so the
    flow's own noise sets the gate.
    """
    w = np.zeros(x.shape[0])
    c = gate_px
    for it in range(iters):
        r = residuals(x, y, qx, qy, f, R, valid)
        if it > 0:
            used = r[w > 0.0]
            if used.shape[0] < 3:
                break
            c = max(RAYLEIGH_K * np.median(used) / RAYLEIGH_MEDIAN, MIN_SCALE_PX)
        for i in range(r.shape[0]):
            t = r[i] / c
            w[i] = (1.0 - t * t) ** 2 if t < 1.0 else 0.0
        if (w > 0.0).sum() < 3:
            break
        R = fit(x, y, qx, qy, f, R, w, 2)
    return R
