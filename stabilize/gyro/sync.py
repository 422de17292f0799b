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

from dataclasses import dataclass
from functools import partial

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro.axes import signed_permutations
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.motion.track import MIN_BAND_SUPPORT, VisualTrack
from stabilize.video.decode import frame_interval

GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0
MIN_CORRELATION = 0.6  # of angular speeds, below which a log does not match the video
# The video's turn over the gyro's (motion_scale) outside which the two do not measure
# the same motion. A matched log reads about 1: phone-cc9 1.01 at its calibrated f, the
# rendered sample 1.00, karma 0.88 at the 69° default (pitch and yaw scale with f_true/f,
# and its lens is wider). In-camera stabilisation turns the video far less than its gyro:
# max-heromode 0.17, its speeds still correlating at 0.90; hero7 0.02. Outside the wider
# bounds no focal length explains it: a log of degrees read as radians reads 1/57.
MOTION_SCALE = (0.5, 2.0)
IMPOSSIBLE_SCALE = (0.1, 10.0)
MIN_COVERAGE = 0.8  # share of the frame pairs the log must cover (camera logs stop early)
MAX_DRIFT = 2e-3  # clock-rate difference searched with fit_drift (crystals: ~1e-5..1e-4)
MAX_READOUT_STDERR = 0.15  # of a frame interval: a less certain readout is not used
# A readout within this many σ of 0, or under MIN_READOUT, cannot be told from none: a
# global shutter (the rendered global-shutter sample read 0.5 ms against its gyro, and
# was corrected by it). The video's own estimate (stabilize.shutter) keeps the same rule.
SIGNIFICANT = 3.0
MIN_READOUT = 0.001  # s


def motion_scale(visual: NDArray, gyro: NDArray) -> float:
    """How far the video turns for each radian its gyro turns: the least-squares scale
    of the visual rotation vectors on the gyro's, Σ v·g / Σ g·g, over the frame pairs'
    rotations (N, 3, 3) in camera axes.

    >>> R = so3.exp_so3(np.array([[0.01, 0.0, 0.0], [0.0, -0.02, 0.005]]))
    >>> round(motion_scale(so3.exp_so3(0.5 * so3.log_so3(R)), R), 6)
    0.5
    """
    v, g = so3.log_so3(visual), so3.log_so3(gyro)
    return float(np.sum(v * g) / max(np.sum(g * g), 1e-300))


@dataclass(frozen=True)
class SyncOptions:
    """What is given, and what is searched, when a log is synchronised to a video: an
    ``offset`` (s), the axes ``R_cam_imu`` or a ``readout`` (s) given are kept (None:
    estimated); ``search`` is the offset range, ± s; ``fit_drift`` also fits a clock drift.
    ``readout_source`` says where a readout given came from (``given``, ``log``, ``lens``)."""

    offset: float | None = None
    R_cam_imu: NDArray | None = None
    readout: float | None = 0.0
    fit_drift: bool = False
    search: float = 1.0
    readout_source: str = "given"

    def synchronise(self, log: GyroLog, track: VisualTrack) -> Sync:
        """:func:`synchronise` with these options."""
        return synchronise(
            log,
            track,
            search=(-self.search, self.search),
            offset=self.offset,
            R_cam_imu=self.R_cam_imu,
            readout=self.readout,
            fit_drift=self.fit_drift,
            readout_source=self.readout_source,
        )


@dataclass(frozen=True)
class Sync:
    offset: float  # s, gyro clock minus video clock, at the first row of each frame
    R_cam_imu: NDArray[np.float64]
    bias: NDArray[np.float64]  # rad/s, in IMU axes
    correlation: float  # of the angular speeds at the offset
    readout: float = 0.0  # s, rolling-shutter readout (first to last row); 0: global
    # where the readout came from: given (or the log's, the lens profile's), "estimated",
    # or "none" where the estimate was refused (0 is then taken)
    readout_source: str = "given"
    drift: float = 0.0  # gyro clock rate minus video clock rate (1e-6 = 1 ppm)
    origin: float = 0.0  # video time at which ``offset`` holds exactly
    searched_whole_log: bool = False  # the log's clock lay outside the search range

    @property
    def readout_estimated(self) -> bool:
        """Whether the readout was estimated from the bands (not given, not refused)."""
        return self.readout_source == "estimated"

    def lag(self, track: VisualTrack) -> NDArray[np.float64]:
        """Per pair, when its rotation was seen after the first row: readout × mean height."""
        return self.readout * track.rows

    def clock(self, times: NDArray) -> NDArray[np.float64]:
        """Video times as the gyro clock runs (before the offset): t + drift·(t - origin)."""
        return drifted(times, self.drift, self.origin)


def drifted(times: NDArray, drift: float, origin: float) -> NDArray[np.float64]:
    """t + drift·(t - origin): a gyro clock running at 1 + drift times the video's rate."""
    times = np.asarray(times, dtype=np.float64)
    return times + drift * (times - origin)


def visual_rates(times: NDArray, R: NDArray) -> NDArray[np.float64]:
    """ω_vis per frame interval (N-1, 3), camera axes, rad/s."""
    return -so3.log_so3(R) / np.diff(times)[:, None]


class IntervalRates:
    """Mean gyro rate over video-time intervals, for any clock offset."""

    def __init__(self, log: GyroLog) -> None:
        self.log = log
        steps = np.diff(log.times)[:, None] * 0.5 * (log.rates[1:] + log.rates[:-1])
        self.integral = np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])

    def __call__(
        self, times: NDArray, offset: float, lag: NDArray | float = 0.0
    ) -> NDArray[np.float64]:
        """(N-1, 3) mean ω_imu over [t_k, t_{k+1}] + lag_k, shifted onto the gyro clock;
        NaN rows for intervals the log does not cover."""
        a, b = self._ends(times, offset, lag)
        I = [
            np.stack([np.interp(g, self.log.times, self.integral[:, i]) for i in range(3)], -1)
            for g in (a, b)
        ]
        rates = (I[1] - I[0]) / (b - a)[:, None]
        rates[~self.covered(times, offset, lag)] = np.nan
        return rates

    @staticmethod
    def _ends(times: NDArray, offset: float, lag: NDArray | float) -> tuple[NDArray, NDArray]:
        g = np.asarray(times) + offset
        return g[:-1] + lag, g[1:] + lag

    def covered(self, times: NDArray, offset: float, lag: NDArray | float = 0.0) -> NDArray:
        """Which frame intervals lie inside the log at this offset."""
        lo, hi = self.log.span
        a, b = self._ends(times, offset, lag)
        return (a >= lo) & (b <= hi)

    def covers(self, times: NDArray, offset: float, lag: NDArray | float = 0.0) -> bool:
        """Whether enough of the clip (MIN_COVERAGE) lies inside the log."""
        return bool(self.covered(times, offset, lag).mean() >= MIN_COVERAGE)


def coarse_offset(
    gyro: IntervalRates, times: NDArray, w_vis: NDArray, search: tuple[float, float]
) -> tuple[float, float, bool]:
    """(offset, correlation, whole) maximising the correlation of angular speeds on a
    1 ms grid over the ``search`` range.

    A log on a clock of its own (an Android boot clock: its first sample at 123456 s)
    overlaps the video at no offset in that range; then every offset at which the log
    covers the video is searched (``whole`` True), coarsely at a quarter of a frame
    interval, then to 1 ms around the best.
    """
    best = _best_offset(gyro, times, w_vis, np.arange(search[0], search[1] + 5e-4, 1e-3))
    if np.isfinite(best[1]):
        return (*best, False)
    lo, hi = gyro.log.span
    first, last = float(times[0]), float(times[-1])
    if hi - lo >= MIN_COVERAGE * (last - first):
        step = 0.25 * frame_interval(times)
        everywhere = np.arange(lo - first, hi - last + step, step)
        coarse = _best_offset(gyro, times, w_vis, everywhere)
        if np.isfinite(coarse[1]):
            fine = np.arange(coarse[0] - step, coarse[0] + step + 5e-4, 1e-3)
            return (*_best_offset(gyro, times, w_vis, fine), True)
        if any(gyro.covers(times, delta) for delta in everywhere):
            # it was said not to cover a 0.03 s video that its 20 s lay over
            raise GyroError(
                f"{gyro.log.source}: the gyro log covers the video, but its angular speed "
                "and the video's do not vary enough to be matched (a camera held still, a "
                "steady turn, or too few frames): give the offset, --gyro-offset SECONDS"
            )
    raise GyroError(
        f"{gyro.log.source}: the gyro log, {lo:.2f}–{hi:.2f} s on its clock "
        f"({hi - lo:.2f} s), does not cover the video, {first:.2f}–{last:.2f} s "
        f"({last - first:.2f} s), at any offset"
    )


def _best_offset(
    gyro: IntervalRates, times: NDArray, w_vis: NDArray, offsets: NDArray
) -> tuple[float, float]:
    """(offset, correlation) of the best-correlated offset at which the log covers."""
    best = (0.0, -np.inf)
    for delta in offsets:
        if gyro.covers(times, delta):
            r = speed_correlation(gyro, times, w_vis, delta)
            if np.isfinite(r) and r > best[1]:
                best = (float(delta), r)
    return best


def speed_correlation(
    gyro: IntervalRates, times: NDArray, w_vis: NDArray, offset: float, lag: NDArray | float = 0.0
) -> float:
    """Correlation of the visual and the gyro angular speeds (axis-free)."""
    speed = np.linalg.norm(gyro(times, offset, lag), axis=1)
    ok = np.isfinite(speed)
    a, b = np.linalg.norm(w_vis, axis=1)[ok], speed[ok]
    if len(a) < 2 or np.ptp(a) == 0 or np.ptp(b) == 0:  # nothing varies: none (no warning)
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def fit_axes(w_vis: NDArray, w_imu: NDArray, R: NDArray | None = None) -> tuple[NDArray, NDArray]:
    """(R_cam_imu, bias) with w_vis ≈ R (w_imu - bias), least squares.

    Without a given R: the best signed permutation, then Kabsch on centred rates, kept
    only where the data support it (:func:`refinement_is_supported`). Cameras mount their
    IMU along the sensor's axes, and the visual estimate's errors correlate with the
    motion a little (parallax while walking or driving), so an unsupported refinement
    would turn that error into a tilt of the axes (6.7° on phone-cc9).
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
        if refinement_is_supported(b, a @ R.T, a @ kabsch.T):
            R = kabsch
    bias = w_imu.mean(0) - R.T @ w_vis.mean(0)
    return R, bias


def refinement_is_supported(w_vis: NDArray, fit_a: NDArray, fit_b: NDArray) -> bool:
    """Whether the 3 extra parameters of fit b (Kabsch) over fit a (a permutation) pay
    for themselves by the Bayesian information criterion, n ln(SSR_a/SSR_b) > 3 ln n, with
    n the residuals' effective count (their lag-1 autocorrelation ρ: n (1-ρ)/(1+ρ))."""
    r_a, r_b = w_vis - fit_a, w_vis - fit_b
    ssr_a, ssr_b = float(np.sum(r_a**2)), float(np.sum(r_b**2))
    if ssr_b <= 0.0 or len(r_b) < 3:
        return ssr_b < ssr_a
    lag1 = np.sum(r_b[1:] * r_b[:-1]) / ssr_b
    rho = float(np.clip(lag1, 0.0, 0.95))
    n = r_b.size * (1.0 - rho) / (1.0 + rho)
    return n * np.log(ssr_a / ssr_b) > 3.0 * np.log(n)


def rate_error(
    gyro: IntervalRates,
    times: NDArray,
    w_vis: NDArray,
    R: NDArray,
    bias: NDArray,
    offset: float,
    lag: NDArray | float = 0.0,
) -> float:
    """Mean squared |w_vis - R (w_gyro - b)|² at an offset; inf where the log falls short."""
    if not gyro.covers(times, offset, lag):
        return np.inf
    return float(np.nanmean((w_vis - (gyro(times, offset, lag) - bias) @ R.T) ** 2))


def golden_section(cost, lo: float, hi: float, tol: float = 1e-5) -> float:
    """The minimiser of a unimodal ``cost`` on [lo, hi], to ``tol``."""
    a, b = lo, hi
    c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    fc, fd = cost(c), cost(d)
    while b - a > tol:
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - GOLDEN * (b - a)
            fc = cost(c)
        else:
            a, c, fc = c, d, fd
            d = a + GOLDEN * (b - a)
            fd = cost(d)
    return 0.5 * (a + b)


def estimate_readout(
    gyro: IntervalRates, track: VisualTrack, R: NDArray, bias: NDArray, offset: float
) -> tuple[float, float | None]:
    """(offset of the first row, readout) from the rotations of horizontal bands.

    Each band's rotations are seen at its own capture time: its best offset is
    δ_b = δ_0 + readout · ȳ_b. A weighted line through (ȳ_b, δ_b) gives both; bands
    whose rates fit poorly (little texture, a moving subject) weigh less. The readout is
    kept within [0, one frame interval]. Without three usable bands, or when the slope is
    too uncertain (smooth, slow motion dates the bands poorly), the answer is None and
    ``offset`` is returned unchanged.
    """
    frame = frame_interval(track.times)
    heights, offsets, weights = [], [], []
    for R_b, rows, support in zip(track.bands, track.band_rows, track.band_support, strict=True):
        if np.median(support) < MIN_BAND_SUPPORT:
            continue
        w_vis = visual_rates(track.times, R_b)
        delta = golden_section(
            partial(rate_error, gyro, track.times, w_vis, R, bias),
            offset - frame,
            offset + frame,
        )
        residual = rate_error(gyro, track.times, w_vis, R, bias, delta)
        if np.isfinite(residual):
            heights.append(float(np.mean(rows)))
            offsets.append(delta)
            weights.append(1.0 / max(residual, 1e-12))
    if len(heights) < 3:
        return offset, None
    x, y, w = np.array(heights), np.array(offsets), np.array(weights)
    slope, intercept = np.polyfit(x, y, 1, w=np.sqrt(w))
    dof = max(len(x) - 2, 1)
    spread = np.sum(w * (x - np.average(x, weights=w)) ** 2)
    sigma2 = np.sum(w * (y - slope * x - intercept) ** 2) / dof
    stderr = float(np.sqrt(sigma2 / spread)) if spread > 0 else np.inf
    # A slope that the bands do not pin down, or one no shutter can have, is no estimate.
    if stderr > MAX_READOUT_STDERR * frame or not -0.1 * frame < slope < 1.1 * frame:
        return offset, None
    readout = float(np.clip(slope, 0.0, frame))
    if readout < max(SIGNIFICANT * stderr, MIN_READOUT):
        readout = 0.0  # a global shutter: the offset is the bands' mean, every row's
    return float(np.average(y - readout * x, weights=w)), readout


def refine_offset_and_axes(
    gyro: IntervalRates,
    times: NDArray,
    w_vis: NDArray,
    offset: float,
    lag: NDArray | float,
    fit_offset: bool,
    R_given: NDArray | None,
    R: NDArray,
    bias: NDArray,
) -> tuple[float, NDArray, NDArray]:
    """Alternate a golden-section search of the offset (±5 ms, to 10 µs) with the axes."""
    for _ in range(2):
        if fit_offset:
            offset = golden_section(
                partial(rate_error, gyro, times, w_vis, R, bias, lag=lag),
                offset - 0.005,
                offset + 0.005,
            )
        R, bias = fit_axes(w_vis, gyro(times, offset, lag), R_given)
    return offset, R, bias


def synchronise(
    log: GyroLog,
    track: VisualTrack,
    *,
    search: tuple[float, float] = (-1.0, 1.0),
    offset: float | None = None,
    R_cam_imu: NDArray | None = None,
    readout: float | None = None,
    fit_drift: bool = False,
    max_drift: float = MAX_DRIFT,
    readout_source: str = "given",
) -> Sync:
    """Offset, axes, bias (and readout) of ``log`` against a clip's visual rotations.

    ``offset``, ``R_cam_imu`` or ``readout`` (s) given are kept; only the rest is
    estimated. With frame times already on the gyro clock, pass ``offset=0``. The readout
    is estimated when not given and the track has band rotations; otherwise it is 0 (a
    global shutter, or the offset of the rows the rotations were seen on). ``fit_drift``
    also fits a linear clock drift within ±``max_drift`` (long clips; a few ms over the
    clip are needed to see it). ``readout_source`` names where a readout given came from.
    """
    gyro = IntervalRates(log)
    times = track.times
    w_vis = visual_rates(times, track.rotations)
    if offset is None:
        delta, corr, whole = coarse_offset(gyro, times, w_vis, search)
    else:
        delta, whole = float(offset), False
        if not gyro.covers(times, delta):
            lo, hi = log.span
            raise GyroError(
                f"{log.source}: the gyro log covers {lo:.2f}–{hi:.2f} s on its clock; at "
                f"offset {delta:+.3f} s the video needs {times[0] + delta:.2f}–"
                f"{times[-1] + delta:.2f} s"
            )
        corr = speed_correlation(gyro, times, w_vis, delta)
    R, bias = fit_axes(w_vis, gyro(times, delta), R_cam_imu)
    fit = offset is None
    delta, R, bias = refine_offset_and_axes(gyro, times, w_vis, delta, 0.0, fit, R_cam_imu, R, bias)
    given = readout is not None  # kept as it is
    estimated = not given and track.bands is not None and offset is None
    if estimated:
        delta, readout = estimate_readout(gyro, track, R, bias, delta)
        estimated = readout is not None
    readout = float(readout or 0.0)
    if readout:
        lag = readout * track.rows
        if not estimated and offset is None:
            delta -= readout * float(np.mean(track.rows))  # the content offset → first row
        delta, R, bias = refine_offset_and_axes(
            gyro, times, w_vis, delta, lag, fit, R_cam_imu, R, bias
        )
        corr = speed_correlation(gyro, times, w_vis, delta, lag)
    drift = 0.0
    if fit_drift:
        lag = readout * track.rows

        def cost(eps: float) -> float:
            d = refine_offset_and_axes(
                gyro, drifted(times, eps, times[0]), w_vis, delta, lag, fit, R_cam_imu, R, bias
            )[0]
            return rate_error(gyro, drifted(times, eps, times[0]), w_vis, R, bias, d, lag)

        drift = golden_section(cost, -max_drift, max_drift, tol=1e-7)
        delta, R, bias = refine_offset_and_axes(
            gyro, drifted(times, drift, times[0]), w_vis, delta, lag, fit, R_cam_imu, R, bias
        )
    if not given:
        readout_source = "estimated" if estimated else "none"
    return Sync(delta, R, bias, corr, readout, readout_source, drift, float(times[0]), whole)
