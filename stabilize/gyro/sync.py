"""Synchronising a gyro log with the visual rotation estimate.

The visual estimate gives each frame interval's mean angular velocity in camera axes,
ω_vis = -log(R_t) / Δt (CONVENTIONS.md: R_t = exp(-[ω Δt]×)). The gyro gives ω_imu on its
own clock and axes. We find

* the **offset** δ = gyro clock - video clock: first by cross-correlating the angular
  *speeds* |ω| (axis-free) over the search range on a 1 ms grid, then by minimising the
  full vector error with a golden-section search to 10 µs;
* the **axes** R_cam_imu (ω_cam = R ω_imu): the best of the 24 signed axis permutations,
  then a least-squares rotation (Kabsch) together with the gyro's constant **bias**.

Gyro rates are compared as means over each frame interval (a cumulative integral,
interpolated), which is what the visual estimate measures.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro.log import GyroError, GyroLog

GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0
MIN_CORRELATION = 0.6  # of angular speeds, below which a log does not match the video
MIN_COVERAGE = 0.8  # share of the frame pairs the log must cover (camera logs stop early)


@dataclass(frozen=True)
class Sync:
    offset: float  # s, gyro clock minus video clock
    R_cam_imu: NDArray[np.float64]
    bias: NDArray[np.float64]  # rad/s, in IMU axes
    correlation: float  # of the angular speeds at the offset


def signed_permutations() -> list[NDArray[np.float64]]:
    """The 24 rotations that map axes onto signed axes."""
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            M = np.zeros((3, 3))
            M[range(3), perm] = signs
            if np.linalg.det(M) > 0:
                out.append(M)
    return out


def visual_rates(times: NDArray, R: NDArray) -> NDArray[np.float64]:
    """ω_vis per frame interval (N-1, 3), camera axes, rad/s."""
    return -so3.log_so3(R) / np.diff(times)[:, None]


class IntervalRates:
    """Mean gyro rate over video-time intervals, for any clock offset."""

    def __init__(self, log: GyroLog) -> None:
        self.log = log
        steps = np.diff(log.times)[:, None] * 0.5 * (log.rates[1:] + log.rates[:-1])
        self.integral = np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])

    def __call__(self, times: NDArray, offset: float) -> NDArray[np.float64]:
        """(N-1, 3) mean ω_imu over [t_k, t_{k+1}] shifted onto the gyro clock; NaN rows
        for intervals the log does not cover."""
        g = np.asarray(times) + offset
        I = np.stack([np.interp(g, self.log.times, self.integral[:, a]) for a in range(3)], -1)
        rates = np.diff(I, axis=0) / np.diff(times)[:, None]
        rates[~self.covered(times, offset)] = np.nan
        return rates

    def covered(self, times: NDArray, offset: float) -> NDArray[np.bool_]:
        """Which frame intervals lie inside the log at this offset."""
        lo, hi = self.log.span
        g = np.asarray(times) + offset
        return (g[:-1] >= lo) & (g[1:] <= hi)

    def covers(self, times: NDArray, offset: float) -> bool:
        """Whether enough of the clip (MIN_COVERAGE) lies inside the log."""
        return bool(self.covered(times, offset).mean() >= MIN_COVERAGE)


def coarse_offset(
    gyro: IntervalRates, times: NDArray, w_vis: NDArray, search: tuple[float, float]
) -> tuple[float, float]:
    """(offset, correlation) maximising the correlation of angular speeds, 1 ms grid."""
    speed_vis = np.linalg.norm(w_vis, axis=1)
    best = (0.0, -np.inf)
    for delta in np.arange(search[0], search[1] + 5e-4, 1e-3):
        if not gyro.covers(times, delta):
            continue
        speed = np.linalg.norm(gyro(times, delta), axis=1)
        ok = np.isfinite(speed)
        r = np.corrcoef(speed_vis[ok], speed[ok])[0, 1]
        if np.isfinite(r) and r > best[1]:
            best = (float(delta), float(r))
    if not np.isfinite(best[1]):
        lo, hi = gyro.log.span
        raise GyroError(
            f"{gyro.log.source}: the gyro log ({hi - lo:.2f} s) does not cover the video "
            f"({times[-1] - times[0]:.2f} s) at any offset in {search[0]:+.2f}…{search[1]:+.2f} s"
        )
    return best


def fit_axes(w_vis: NDArray, w_imu: NDArray, R: NDArray | None = None) -> tuple[NDArray, NDArray]:
    """(R_cam_imu, bias) with w_vis ≈ R (w_imu - bias), least squares.

    Without a given R: the best signed permutation, then Kabsch on centred rates.
    """
    ok = np.isfinite(w_imu).all(axis=1)
    w_vis, w_imu = w_vis[ok], w_imu[ok]
    if R is None:
        costs = [np.sum((w_vis - w_imu @ P.T) ** 2) for P in signed_permutations()]
        R = signed_permutations()[int(np.argmin(costs))]
        a, b = w_imu - w_imu.mean(0), w_vis - w_vis.mean(0)
        U, _, Vt = np.linalg.svd(a.T @ b)
        D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
        kabsch = Vt.T @ D @ U.T
        # Keep the permutation's answer if Kabsch wanders off (too little motion).
        if so3.angular_error_deg(kabsch, R) < 20.0:
            R = kabsch
    bias = w_imu.mean(0) - R.T @ w_vis.mean(0)
    return R, bias


def refine_offset(
    gyro: IntervalRates, times: NDArray, w_vis: NDArray, R: NDArray, bias: NDArray, start: float
) -> float:
    """Golden-section search of Σ|w_vis - R (w_gyro(δ) - b)|² within ±5 ms, to 10 µs."""

    def cost(delta: float) -> float:
        if not gyro.covers(times, delta):
            return np.inf
        return float(np.nanmean((w_vis - (gyro(times, delta) - bias) @ R.T) ** 2))

    a, b = start - 0.005, start + 0.005
    c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    fc, fd = cost(c), cost(d)
    while b - a > 1e-5:
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - GOLDEN * (b - a)
            fc = cost(c)
        else:
            a, c, fc = c, d, fd
            d = a + GOLDEN * (b - a)
            fd = cost(d)
    return 0.5 * (a + b)


def synchronise(
    log: GyroLog,
    times: NDArray,
    R_visual: NDArray,
    *,
    search: tuple[float, float] = (-1.0, 1.0),
    offset: float | None = None,
    R_cam_imu: NDArray | None = None,
) -> Sync:
    """Offset, axes and bias of ``log`` against the visual rotations at ``times``.

    ``offset`` or ``R_cam_imu`` given are kept (only the rest is estimated). With frame
    times already on the gyro clock, pass ``offset=0``.
    """
    gyro = IntervalRates(log)
    w_vis = visual_rates(times, R_visual)
    if offset is None:
        delta, corr = coarse_offset(gyro, times, w_vis, search)
    else:
        delta = float(offset)
        if not gyro.covers(times, delta):
            raise GyroError(
                f"{log.source}: the gyro log does not cover the video at offset {delta:+.3f} s"
            )
        speed = np.linalg.norm(gyro(times, delta), axis=1)
        ok = np.isfinite(speed)
        corr = float(np.corrcoef(np.linalg.norm(w_vis, axis=1)[ok], speed[ok])[0, 1])
    R, bias = fit_axes(w_vis, gyro(times, delta), R_cam_imu)
    if offset is None:
        for _ in range(2):
            delta = refine_offset(gyro, times, w_vis, R, bias, delta)
            R, bias = fit_axes(w_vis, gyro(times, delta), R_cam_imu)
    return Sync(delta, R, bias, corr)
