"""The camera's continuous attitude from the rotations of horizontal bands.

Under a rolling shutter of readout r, row y (0 top .. 1 bottom) of frame k is captured at
t_k + r·y, so the rotation pass 1 measured on band b of pair k, from vectors of mean
height y_bk, is the turn between t_k + r·y_bk and t_{k+1} + r·y_bk. With the attitude
written as an accumulated rotation vector Ω(t) (small turns per frame add up to first
order; CONVENTIONS.md's sign, θ = -log R),

    θ_bk ≈ Ω(t_{k+1} + r·y_bk) - Ω(t_k + r·y_bk).

Ω is a cubic B-spline with a knot per frame interval. For a given r its coefficients are a
sparse linear least-squares problem over every band of every pair (Cauchy-weighted, so a
band that saw a moving subject counts little), with a light penalty on the coefficients'
second differences that bridges frames no band measured. The rates dΩ/dt are then a
"visual gyro": :func:`visual_attitude` integrates them as the gyro mode does.

A band whose turn differs from its whole frame's by more than a rolling shutter could
make it differ is left out before the fit (:func:`agrees_with_frame`): a subject close to
the lens can fill most of a frame's rows and win each of their bands' votes, which the
whole frame's vote, with the static scene's vectors from every row, does not give it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sparse
from numpy.typing import NDArray
from scipy.interpolate import BSpline
from scipy.sparse.linalg import spsolve

from rotation import so3
from stabilize.gyro.integrate import Attitude, attitude
from stabilize.gyro.log import GyroLog
from stabilize.motion.track import MIN_BAND_SUPPORT, VisualTrack
from stabilize.video.decode import frame_interval

BEND = 1e-3  # weight of the coefficients' second differences (rad², against the data's)
# How far a band's turn may differ from its whole frame's beyond what a shutter explains:
# on the real clips at most 1.09° (karma, max-heromode), 1.49° (phone-cc9) and 1.63°
# (hero7), under 0.2% of the bands past 1.5° (phone-cc9 at 31°, hero7). On cockatoo, a
# bird filling the frame, 8% were past it, up to 13°: nine of twelve bands of two blurred
# pairs read its 3.5–4.8° sweep, the whole frame 0.3°, and the fitted attitude turned the
# frame 3.5°, a jump of 88 px in two frames that the original does not have
GATE_DEG = 1.5
IRLS_STEPS = 3
RATE_SAMPLES = 8  # rate samples per frame interval handed to the integration


@dataclass(frozen=True)
class Bands:
    """What the fit reads of a track: the band turns θ_bk (M, 3), the times of their
    rows' first and second capture (M,), and which are usable."""

    theta: NDArray[np.float64]
    heights: NDArray[np.float64]  # (M,) y_bk, 0 top .. 1 bottom
    starts: NDArray[np.float64]  # (M,) t_k
    ends: NDArray[np.float64]  # (M,) t_{k+1}
    usable: NDArray[np.bool_]

    @classmethod
    def of(cls, track: VisualTrack) -> Bands:
        if track.bands is None:
            raise ValueError("the track has no band rotations (pass 1 ran without bands)")
        B = len(track.bands)
        theta = -so3.log_so3(track.bands).reshape(-1, 3)
        usable = (track.band_support >= MIN_BAND_SUPPORT) & agrees_with_frame(track)
        usable = usable.ravel() & np.isfinite(theta).all(1)
        starts = np.tile(track.times[:-1], B)
        ends = np.tile(track.times[1:], B)
        return cls(theta, track.band_rows.ravel(), starts, ends, usable)


def agrees_with_frame(track: VisualTrack) -> NDArray[np.bool_]:
    """(B, N-1): whether each band's turn θ_bk lies within ``GATE_DEG`` of its whole
    frame's θ_k, beyond what a rolling shutter explains. Read at row y_bk rather than at
    the whole frame's mean row ȳ_k, the same camera turns by at most |y_bk - ȳ_k| times
    how much its turn changes across a frame interval (a readout is at most one), and
    that change is bounded by the larger step to a neighbouring pair's θ:

        |θ_bk - θ_k| ≤ |y_bk - ȳ_k| · max(|θ_k - θ_k-1|, |θ_k+1 - θ_k|) + GATE_DEG."""
    whole = so3.log_so3(track.rotations)  # (N-1, 3)
    step = np.linalg.norm(np.diff(whole, axis=0), axis=1)
    change = np.maximum(np.r_[step, 0.0], np.r_[0.0, step])
    explained = np.abs(track.band_rows - track.rows[None]) * change[None]
    apart = np.linalg.norm(so3.log_so3(track.bands) - whole[None], axis=2)
    return apart <= explained + np.radians(GATE_DEG)


@dataclass(frozen=True)
class Spline:
    """Ω(t) = Σ c_j B_j(t), cubic, with a knot per frame interval."""

    knots: NDArray[np.float64]
    coefficients: NDArray[np.float64]  # (J, 3)

    def rates(self, t: NDArray) -> NDArray[np.float64]:
        """dΩ/dt (..., 3) at times t, rad/s."""
        return BSpline(self.knots, self.coefficients, 3).derivative()(t)


def knots_for(times: NDArray) -> NDArray[np.float64]:
    """Clamped cubic knots a frame interval apart, reaching a frame interval before the
    first frame and two past the last (the bottom rows of the last pair)."""
    step = frame_interval(times)
    inner = np.arange(times[0] - step, times[-1] + 2.5 * step, step)
    return np.r_[[inner[0]] * 3, inner, [inner[-1]] * 3]


def fit_attitude(
    bands: Bands,
    readout: float,
    knots: NDArray,
    scale: float,
    weights: NDArray | None = None,
    steps: int = IRLS_STEPS,
) -> tuple[Spline, NDArray, NDArray]:
    """(Ω, each band's residual length (M,), its next Cauchy weight (M,)) for a readout
    (s), after ``steps`` reweighted solves; ``scale`` (rad) is the Cauchy loss's;
    ``weights`` (M,) start the reweighting (default: the usable bands, equally)."""
    lag = readout * bands.heights
    A = BSpline.design_matrix(bands.ends + lag, knots, 3) - BSpline.design_matrix(
        bands.starts + lag, knots, 3
    )
    J = A.shape[1]
    second = sparse.diags([1.0, -2.0, 1.0], [0, 1, 2], shape=(J - 2, J))
    prior = BEND * (second.T @ second) + 1e-9 * sparse.eye(J)
    w = bands.usable.astype(float) if weights is None else weights
    for _ in range(steps):
        normal = (A.T @ sparse.diags(w) @ A + prior).tocsc()
        c = np.asarray(spsolve(normal, A.T @ (w[:, None] * bands.theta))).reshape(J, 3)
        error = np.linalg.norm(bands.theta - A @ c, axis=1)
        w = bands.usable / (1.0 + (error / scale) ** 2)
    return Spline(knots, c), error, w


def visual_attitude(spline: Spline, times: NDArray) -> Attitude:
    """The attitude G(t) the spline's rates integrate to, sampled ``RATE_SAMPLES`` times
    a frame interval over the knots' span (video clock)."""
    lo, hi = spline.knots[0], spline.knots[-1]
    count = int(np.ceil((hi - lo) / frame_interval(times) * RATE_SAMPLES)) + 1
    at = np.linspace(lo, hi, count)
    return attitude(GyroLog(at, spline.rates(at), "the video"))
