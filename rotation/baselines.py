"""Baseline estimators for the paper's Table 1 comparison, with the same result type.

* :func:`least_squares`: the Longuet-Higgins system over all vectors, not robust.
* :func:`ransac`: the same model in RANSAC with minimal two-vector samples.
* :func:`five_point`: OpenCV's ``findEssentialMat`` (Nistér) and ``recoverPose``.

All sample the flow on the same grid as :class:`rotation.HoughEstimator`.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from rotation import so3
from rotation.camera import default_center, intrinsics
from rotation.result import RotationEstimate
from rotation.sampling import check_flows, sample_flows, sample_grid


def _samples(flow: NDArray, center, step):
    flow = np.asarray(flow)
    if flow.ndim != 3:
        raise ValueError(f"flow must have shape (H, W, 2), got {flow.shape}")
    size = flow.shape[:2]
    center = default_center(size) if center is None else center
    flow = check_flows(flow, size, stacked=False)
    grid = sample_grid(size, step, center)
    u, v, valid = sample_flows(flow, grid)
    return grid, u, v, valid


def lh_system(x: NDArray, y: NDArray, f: float) -> NDArray[np.float64]:
    """Stacked Longuet-Higgins matrices (N, 2, 3): (u, v) = M (A, B, C)."""
    M = np.empty((len(x), 2, 3))
    M[:, 0, 0], M[:, 0, 1], M[:, 0, 2] = x * y / f, -(f * f + x * x) / f, y
    M[:, 1, 0], M[:, 1, 1], M[:, 1, 2] = (f * f + y * y) / f, -x * y / f, -x
    return M


def _solve_lh(M: NDArray, uv: NDArray) -> NDArray[np.float64]:
    """Least-squares ω over the vectors in the leading axes of M (…, k, 2, 3)."""
    A = M.reshape(*M.shape[:-3], -1, 3)
    b = uv.reshape(*uv.shape[:-2], -1)
    AtA = np.swapaxes(A, -1, -2) @ A
    Atb = np.swapaxes(A, -1, -2) @ b[..., None]
    return np.linalg.solve(AtA, Atb)[..., 0]


def _from_omega(omega: NDArray, support: float, inliers: NDArray) -> RotationEstimate:
    # ω is the camera's own small-angle rotation, so R_t = exp(-[ω]×).
    return RotationEstimate.from_matrix(so3.exp_so3(-omega), support, inliers)


def _identity(shape: tuple[int, int]) -> RotationEstimate:
    return RotationEstimate.from_matrix(np.eye(3), 0.0, np.zeros(shape, bool))


def least_squares(flow: NDArray, focal: float, *, center=None, step: int = 15) -> RotationEstimate:
    """Longuet-Higgins least squares over every valid sampled vector."""
    grid, u, v, valid = _samples(flow, center, step)
    if valid.sum() < 2:
        return _identity(grid.shape)
    M = lh_system(grid.x[valid], grid.y[valid], focal)
    uv = np.stack([u[valid], v[valid]], -1)
    return _from_omega(_solve_lh(M, uv), 1.0, valid.reshape(grid.shape))


def ransac(
    flow: NDArray,
    focal: float,
    *,
    iterations: int = 500,
    threshold_px: float = 1.0,
    seed: int = 0,
    center=None,
    step: int = 15,
) -> RotationEstimate:
    """RANSAC on the Longuet-Higgins model with minimal samples of two vectors.

    Every hypothesis is scored at once (vectorised); the best is refitted to its
    inliers by least squares.
    """
    grid, u, v, valid = _samples(flow, center, step)
    idx = np.flatnonzero(valid)
    if len(idx) < 2:
        return _identity(grid.shape)
    M = lh_system(grid.x[idx], grid.y[idx], focal)
    uv = np.stack([u[idx], v[idx]], -1)
    rng = np.random.default_rng(seed)
    pairs = np.stack([rng.choice(len(idx), 2, replace=False) for _ in range(iterations)])
    omegas = _solve_lh(M[pairs], uv[pairs])  # (iterations, 3)
    predicted = np.einsum("nij,kj->kni", M, omegas)
    counts = (np.linalg.norm(predicted - uv, axis=-1) < threshold_px).sum(axis=1)
    best = omegas[np.argmax(counts)]
    inl = np.linalg.norm(M @ best - uv, axis=-1) < threshold_px
    if inl.sum() >= 2:
        best = _solve_lh(M[inl], uv[inl])
        inl = np.linalg.norm(M @ best - uv, axis=-1) < threshold_px
    mask = np.zeros(valid.shape, bool)
    mask[idx[inl]] = True
    return _from_omega(best, inl.mean(), mask.reshape(grid.shape))


def five_point(
    flow: NDArray,
    focal: float,
    *,
    threshold_px: float = 1.0,
    confidence: float = 0.999,
    max_iters: int = 1000,
    center=None,
    step: int = 15,
) -> RotationEstimate:
    """Essential matrix by Nistér's five-point solver in RANSAC, then ``recoverPose``.

    Under pure rotation the essential matrix is undefined, which is this family's
    known weakness on distant scenes; the result is then whatever OpenCV returns.
    """
    grid, u, v, valid = _samples(flow, center, step)
    if valid.sum() < 5:
        return _identity(grid.shape)
    cx, cy = default_center(flow.shape[:2]) if center is None else center
    K = intrinsics(focal, flow.shape[:2], (cx, cy))
    p0 = np.stack([grid.x[valid] + cx, grid.y[valid] + cy], -1)
    p1 = p0 + np.stack([u[valid], v[valid]], -1)
    E, mask = cv2.findEssentialMat(
        p0, p1, K, method=cv2.RANSAC, prob=confidence, threshold=threshold_px, maxIters=max_iters
    )
    if E is None or E.shape != (3, 3):
        E = E[:3] if E is not None and E.shape[0] > 3 else None
    if E is None:
        return _identity(grid.shape)
    _, R, _, pose_mask = cv2.recoverPose(E, p0, p1, K, mask=mask)
    inl = np.zeros(valid.shape, bool)
    inl[np.flatnonzero(valid)] = pose_mask.ravel() > 0
    # recoverPose gives X₁ = R X₀ + t, which is R_t of CONVENTIONS.md.
    return RotationEstimate.from_matrix(R, inl.sum() / valid.sum(), inl.reshape(grid.shape))
