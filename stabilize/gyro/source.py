"""The gyro as the source of the camera path: filtering, synchronising, integrating."""

from __future__ import annotations

from dataclasses import replace

from scipy.signal import butter, filtfilt

from stabilize.gyro.integrate import Attitude, attitude
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.sync import MIN_CORRELATION, Sync, SyncOptions
from stabilize.motion.track import VisualTrack


def lowpass(log: GyroLog, cutoff_hz: float) -> GyroLog:
    """Zero-phase 2nd-order Butterworth low-pass of the rates (no lag)."""
    nyquist = 0.5 * log.rate_hz
    if not 0 < cutoff_hz < nyquist:
        raise GyroError(f"--gyro-lpf must be between 0 and {nyquist:.0f} Hz, got {cutoff_hz}")
    b, a = butter(2, cutoff_hz, fs=log.rate_hz)
    return replace(log, rates=filtfilt(b, a, log.rates, axis=0))


def gyro_rotations(
    log: GyroLog, track: VisualTrack, options: SyncOptions | None = None
) -> tuple[Attitude, Sync]:
    """The camera attitude from the gyro, synchronised against the visual estimate, bias
    removed, in camera axes on the gyro clock (video time + ``sync.offset``).

    Refuses a log whose motion does not match the video's: stabilising from it would
    shake the clip instead.
    """
    sync = (options or SyncOptions()).synchronise(log, track)
    if sync.correlation < MIN_CORRELATION:
        raise GyroError(
            f"{log.source}: the gyro's motion does not match the video's (speed correlation "
            f"{sync.correlation:.2f}); check the log, or give --gyro-offset and --gyro-axes"
        )
    unbiased = replace(log, rates=log.rates - sync.bias)
    return attitude(unbiased, sync.R_cam_imu), sync
