"""Visual rotation estimates against a gyroscope: per-pair errors, summary, plots, warning.

The gyro is synchronised to the visual estimate (:mod:`stabilize.gyro.sync`), its bias
removed, and integrated over each frame interval (:mod:`stabilize.gyro.integrate`). The
angular error of each pair is θ(R_vis R_gyroᵀ); the AAE is their mean, as in the paper.

A loud warning is raised, never a silent success, when the two disagree too much to be
trusted: the angular speeds barely correlate (a wrong log, or a clip stabilised in the
camera); the video turns far less or far more than its gyro (a clip stabilised in the
camera whose speeds still correlate, a log read in the wrong unit); or the error is a
large share of the motion itself.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro import GyroLog, integrate_rotations
from stabilize.gyro.axes import axes_code
from stabilize.gyro.focal import focal_from_gyro
from stabilize.gyro.sync import (
    MIN_CORRELATION,
    MOTION_SCALE,
    IntervalRates,
    Sync,
    SyncOptions,
    motion_scale,
    visual_rates,
)
from stabilize.motion.estimate import READOUT_BANDS
from stabilize.motion.focal import estimate_motion
from stabilize.motion.track import VisualTrack
from stabilize.progress import ProgressFactory, no_progress
from stabilize.settings import Settings
from stabilize.video import VideoInfo
from stabilize.video.atomic import atomic_folder
from stabilize.warp.lens import Lens

MAX_ERROR_SHARE = 1.0  # AAE over the mean rotation per frame: the estimate says nothing
FOCAL_ROUNDS = 3  # re-estimations when fitting the focal length to the gyro
FOCAL_CONVERGED = 0.005  # a relative change of the fitted focal length below which it stops


@dataclass(frozen=True)
class Comparison:
    times: NDArray  # (N,) video clock
    visual: NDArray  # (N-1, 3, 3)
    gyro: NDArray  # (N-1, 3, 3)
    errors_deg: NDArray  # (N-1,)
    sync: Sync
    focal_px: float
    gyro_rate_hz: float

    @property
    def rate_errors(self) -> NDArray:
        """ω_vis - ω_gyro per pair (N-1, 3), deg/s, camera axes."""
        return np.degrees(
            visual_rates(self.times, self.visual) - visual_rates(self.times, self.gyro)
        )

    def axis_errors_deg(self) -> NDArray:
        """Mean |error| about each camera axis (pitch x, yaw y, roll z), degrees."""
        return np.degrees(np.abs(so3.log_so3(self.visual @ np.swapaxes(self.gyro, -1, -2)))).mean(0)

    def motion_scale(self) -> float:
        """How far the video turns for each radian its gyro turns (about 1 for a
        matched log: :func:`stabilize.gyro.sync.motion_scale`)."""
        return motion_scale(self.visual, self.gyro)

    def warning(self) -> str | None:
        motion = np.degrees(so3.angle(self.gyro)).mean()
        aae = self.errors_deg.mean()
        if self.sync.correlation < MIN_CORRELATION:
            return (
                f"visual and gyro motion barely agree (speed correlation "
                f"{self.sync.correlation:.2f} < {MIN_CORRELATION}): a wrong or mismatched log, "
                "or a clip stabilised in the camera. Do not trust these figures."
            )
        scale = self.motion_scale()
        if scale < MOTION_SCALE[0]:
            return (
                f"the video turns only {100 * scale:.0f}% as much as its gyro (least-squares "
                "scale): a clip stabilised in the camera, whose gyro records the shake it "
                "took out, or a focal length far off (--calibrate-focal). Do not trust these "
                "figures."
            )
        if scale > MOTION_SCALE[1]:
            return (
                f"the video turns {scale:.1f} times as much as its gyro (least-squares scale): "
                "a log in another unit (degrees read as radians?), or a focal length far off. "
                "Do not trust these figures."
            )
        if aae > MAX_ERROR_SHARE * motion:
            return (
                f"the error ({aae:.3f}° per frame) is {100 * aae / motion:.0f}% of the motion "
                f"itself ({motion:.3f}° per frame): the comparison is not meaningful."
            )
        return None

    def summary(self) -> dict:
        err = self.errors_deg
        axes = self.axis_errors_deg()
        rms = np.sqrt(np.mean(self.rate_errors**2, axis=0))
        return {
            "offset_s": self.sync.offset,
            "readout_ms": 1000.0 * self.sync.readout,
            "readout_estimated": self.sync.readout_estimated,
            "readout_source": self.sync.readout_source,
            "drift_ppm": 1e6 * self.sync.drift,
            "aae_deg": float(err.mean()),
            "median_deg": float(np.median(err)),
            "p95_deg": float(np.percentile(err, 95)),
            "aae_pitch_deg": float(axes[0]),
            "aae_yaw_deg": float(axes[1]),
            "aae_roll_deg": float(axes[2]),
            "rms_rate_error_deg_s": [float(v) for v in rms],
            "frames": int(len(err)),
            "R_cam_imu": self.sync.R_cam_imu.tolist(),
            "axes": axes_code(self.sync.R_cam_imu),
            "gyro_bias_rad_s": self.sync.bias.tolist(),
            "speed_correlation": self.sync.correlation,
            "motion_scale": self.motion_scale(),
            "focal_px": self.focal_px,
            "gyro_rate_hz": self.gyro_rate_hz,
            "warning": self.warning(),
        }


def compare(track: VisualTrack, log: GyroLog, sync: Sync, focal: float) -> Comparison:
    """Pairs inside the log's span are compared (camera logs often stop before the video).

    Under a rolling shutter each pair's gyro interval is shifted to the capture time of
    the rows its visual rotation was seen on (``sync.lag``).
    """
    clock = sync.clock(track.times)
    inside = IntervalRates(log).covered(clock, sync.offset, sync.lag(track))
    first, last = np.flatnonzero(inside)[[0, -1]]
    track = track.pairs(first, last + 1)
    unbiased = replace(log, rates=log.rates - sync.bias)
    clock = sync.clock(track.times)
    gyro = integrate_rotations(unbiased, clock, sync.offset, sync.R_cam_imu, sync.lag(track))
    errors = so3.angular_error_deg(track.rotations, gyro)
    return Comparison(track.times, track.rotations, gyro, errors, sync, focal, log.rate_hz)


def compare_video(
    video: str | Path,
    info: VideoInfo,
    log: GyroLog,
    settings: Settings,
    times: NDArray,
    options: SyncOptions,
    *,
    lens: Lens | None = None,
    calibrate_focal: bool = False,
    progress: ProgressFactory | None = None,
) -> Comparison:
    """Estimate a clip's rotations at frame ``times``, synchronise ``log`` to them, and
    compare the two. A readout that ``options`` leaves open (None) is estimated from
    bands of the frame. ``calibrate_focal`` fits the focal length to the gyro
    (:mod:`stabilize.gyro.focal`), estimating the rotations again with each fit, until
    it changes by less than ``FOCAL_CONVERGED`` or ``FOCAL_ROUNDS`` are done.
    """
    bands = READOUT_BANDS if options.readout is None else 0

    def estimate_and_sync(settings: Settings) -> tuple[VisualTrack, Sync, float]:
        advance = progress("estimating", len(times) - 1) if progress else no_progress
        track, focal = estimate_motion(
            video, info, settings, advance, times, bands=bands, lens=lens
        )
        return track, options.synchronise(log, track), focal.px

    track, sync, focal = estimate_and_sync(settings)
    for _ in range(FOCAL_ROUNDS if calibrate_focal else 0):
        fitted = focal_from_gyro(track, log, sync, focal)
        old, focal = focal, fitted
        track, sync, _ = estimate_and_sync(replace(settings, focal=fitted))
        if abs(fitted / old - 1.0) < FOCAL_CONVERGED:
            break
    return compare(track, log, sync, focal)


def write_comparison(folder: str | Path, result: Comparison) -> None:
    """pairs.csv, summary.json and the plots rates.png, error.png, histogram.png: all
    from this run, or, where it fails, the old ones kept."""
    with atomic_folder(folder) as tmp:
        _write_pairs(tmp / "pairs.csv", result)
        (tmp / "summary.json").write_text(json.dumps(result.summary(), indent=2))
        plot_comparison(tmp, result)


def _write_pairs(path: Path, result: Comparison) -> None:
    rv, rg = so3.log_so3(result.visual), so3.log_so3(result.gyro)
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(
            [
                "frame",
                "t",
                "vis_rx",
                "vis_ry",
                "vis_rz",
                "gyro_rx",
                "gyro_ry",
                "gyro_rz",
                "error_deg",
            ]
        )
        for k in range(len(rv)):
            writer.writerow(
                [
                    k,
                    f"{result.times[k]:.6f}",
                    *(f"{v:.9g}" for v in rv[k]),
                    *(f"{v:.9g}" for v in rg[k]),
                    f"{result.errors_deg[k]:.6f}",
                ]
            )


def plot_comparison(folder: Path, result: Comparison) -> None:
    """rates.png (visual against gyro rates), error.png and histogram.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mid = 0.5 * (result.times[1:] + result.times[:-1]) - result.times[0]
    wv = np.degrees(visual_rates(result.times, result.visual))
    wg = np.degrees(visual_rates(result.times, result.gyro))
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    for ax, k, name in zip(axes, range(3), ("x (pitch)", "y (yaw)", "z (roll)"), strict=True):
        ax.plot(mid, wg[:, k], color="0.3", lw=1.5, label="gyro")
        ax.plot(mid, wv[:, k], color="C1", lw=1, label="visual")
        ax.set_ylabel(f"{name} °/s")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right")
    axes[-1].set_xlabel("time from the first frame (s)")
    fig.suptitle(f"Angular rate, camera axes (offset {1000 * result.sync.offset:+.1f} ms)")
    fig.tight_layout()
    fig.savefig(folder / "rates.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(10, 3.5))
    ax.plot(mid, result.errors_deg, color="C3")
    ax.set_xlabel("time from the first frame (s)")
    ax.set_ylabel("angular error (°)")
    ax.set_title(f"Visual vs gyro: AAE {result.errors_deg.mean():.4f}°")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(folder / "error.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.hist(result.errors_deg, bins=40, color="C0")
    ax.set_xlabel("angular error (°)")
    ax.set_ylabel("frame pairs")
    fig.tight_layout()
    fig.savefig(folder / "histogram.png", dpi=110)
    plt.close(fig)
