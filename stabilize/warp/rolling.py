"""Per-row turns of a rolling-shutter frame, as the warp needs them.

Row y of frame k was captured at its own time; D_k(y) is the camera's turn between the
frame's middle row and row y. The correction of that row is C_k D_k(y)ᵀ. Knot rows carry
exact turns, and the warp interpolates between them (:func:`stabilize.warp.sources.through_rows`).
Where the turns come from (a gyro, or the video) is the caller's business.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

KNOTS = 17  # rows per frame with an exact correction; the warp interpolates in between


@dataclass(frozen=True)
class RollingShutter:
    """D_k(y_b) for every frame k at the knot rows y_b."""

    turns: NDArray[np.float64]  # (N, B, 3, 3) D_k(y_b)
    rows: NDArray[np.float64]  # (B,) the knot rows y_b, input pixels

    def corrections(self, C: NDArray, frames: NDArray | slice = slice(None)) -> NDArray[np.float64]:
        """Per-row corrections C_k D_k(y_b)ᵀ (N, B, 3, 3) of the ``frames``' corrections
        C (N, 3, 3)."""
        return C[:, None] @ np.swapaxes(self.turns[frames], -1, -2)

    def frames(self, first: int, stop: int) -> RollingShutter:
        """The turns of frames first..stop-1 alone."""
        return RollingShutter(self.turns[first:stop], self.rows)

    def at(self, frames: NDArray, rows: NDArray) -> NDArray[np.float64]:
        """D_k(y) (n, M, 3, 3) of ``frames`` (n,) at input ``rows`` ((M,) or (n, M)),
        linear between the knot rows (the turns between knots are tiny)."""
        rows = np.broadcast_to(rows, (len(frames), np.shape(rows)[-1]))
        k, frac = between_knots(self.rows, rows)
        below = self.turns[frames[:, None], k]
        return below + frac[..., None, None] * (self.turns[frames[:, None], k + 1] - below)


def between_knots(knots: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    """For rows ``y`` (any shape; clipped to the knots' span), the index k of the knot at
    or above each and the fraction of the way to knot k + 1."""
    y = np.clip(y, knots[0], knots[-1])
    k = np.clip(np.searchsorted(knots, y) - 1, 0, len(knots) - 2)
    return k, (y - knots[k]) / (knots[k + 1] - knots[k])


# s: the correction's strength ramps over this time, so a frame's shape never jumps from
# one frame to the next. The bench's registration reads capped and ramped alike (phone-cc9
# 1.558 / 1.543 px, karma 0.489 / 0.502); one refined to sub-pixel by Lucas–Kanade,
# which the quantisation of ORB's keypoints does not blur, read phone-cc9 1.309 / 1.198
RAMP_S = 0.15


def centre_slopes(rolling: RollingShutter, K: NDArray) -> NDArray[np.float64]:
    """How far each frame's row correction moves the centre column's pixels per row
    (N, 2): the least-squares slope over the knot rows y_b of

        q_b - p_b,  p_b = (c_x, y_b),  q_b = π(K D_k(y_b)ᵀ K⁻¹ p_b),

    against y_b - c_y (the middle row's turn is the identity). Across the frame the
    correction is then nearly the shear-and-stretch [[1, s_x], [0, 1 + s_y]]."""
    cx, cy = K[0, 2], K[1, 2]
    p = np.stack([np.full_like(rolling.rows, cx), rolling.rows, np.ones_like(rolling.rows)], 1)
    rays = p @ np.linalg.inv(K).T  # (B, 3)
    q = np.einsum("nbji,bj->nbi", rolling.turns, rays) @ K.T  # K D(y)ᵀ K⁻¹ p, (N, B, 3)
    moved = q[..., :2] / q[..., 2:] - p[None, :, :2]
    dy = rolling.rows - cy
    return (moved * dy[None, :, None]).sum(1) / (dy**2).sum()


def stretch(slopes: NDArray) -> NDArray[np.float64]:
    """σ_min/σ_max (N,) of [[1, s_x], [0, 1 + s_y]] for slopes (s_x, s_y) (N, 2)."""
    J = np.zeros((len(slopes), 2, 2))
    J[:, 0, 0] = 1.0
    J[:, :, 1] = slopes
    J[:, 1, 1] += 1.0
    s = np.linalg.svd(J, compute_uv=False)
    return s[:, 1] / s[:, 0]


def within_stretch(
    rolling: RollingShutter, K: NDArray, ramp: int, floor: float
) -> tuple[RollingShutter, int]:
    """(the row turns eased, the number of frames eased): D_k(y)^λ_k with λ_k ≤ 1 the
    largest that keeps frame k's :func:`stretch` at least ``floor`` (bisection: the
    stretch falls with λ), then eroded and averaged over ``ramp`` frames either side,
    which keeps every frame within its own λ (each average is of minima over windows
    that hold it) and lets the strength change only gradually."""
    from scipy.ndimage import minimum_filter1d, uniform_filter1d

    from rotation.so3 import exp_so3, log_so3

    slopes = centre_slopes(rolling, K)
    whole = stretch(slopes)
    if len(slopes) == 0 or whole.min() >= floor:
        return rolling, 0
    lo, hi = np.zeros(len(slopes)), np.ones(len(slopes))
    for _ in range(24):  # λ to 1e-7
        mid = 0.5 * (lo + hi)
        good = stretch(slopes * mid[:, None]) >= floor
        lo, hi = np.where(good, mid, lo), np.where(good, hi, mid)
    lam = np.where(whole >= floor, 1.0, lo)
    width = 2 * max(int(ramp), 0) + 1
    lam = uniform_filter1d(minimum_filter1d(lam, width, mode="nearest"), width, mode="nearest")
    n, b = rolling.turns.shape[:2]
    w = log_so3(rolling.turns.reshape(-1, 3, 3)).reshape(n, b, 3)
    eased = RollingShutter(exp_so3(w * lam[:, None, None]), rolling.rows)
    return eased, int((lam < 1.0 - 1e-9).sum())
