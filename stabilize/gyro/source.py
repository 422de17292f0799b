"""The gyro as the source of the camera path: filtering, synchronising, integrating."""

from __future__ import annotations

from numpy.typing import NDArray
from scipy.signal import butter, filtfilt

from stabilize.gyro.integrate import integrate_rotations
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.sync import MIN_CORRELATION, Sync, synchronise


def lowpass(log: GyroLog, cutoff_hz: float) -> GyroLog:
    """Zero-phase 2nd-order Butterworth low-pass of the rates (no lag)."""
    nyquist = 0.5 * log.rate_hz
    if not 0 < cutoff_hz < nyquist:
        raise GyroError(f"--gyro-lpf must be between 0 and {nyquist:.0f} Hz, got {cutoff_hz}")
    b, a = butter(2, cutoff_hz, fs=log.rate_hz)
    return GyroLog(log.times, filtfilt(b, a, log.rates, axis=0), log.source)


def gyro_rotations(
    log: GyroLog,
    times: NDArray,
    R_visual: NDArray,
    *,
    offset: float | None = None,
    R_cam_imu: NDArray | None = None,
    search: float = 1.0,
) -> tuple[NDArray, Sync]:
    """R_t from the gyro, synchronised against the visual estimate, bias removed.

    Refuses a log whose motion does not match the video's: stabilising from it would
    shake the clip instead.
    """
    sync = synchronise(
        log, times, R_visual, search=(-search, search), offset=offset, R_cam_imu=R_cam_imu
    )
    if sync.correlation < MIN_CORRELATION:
        raise GyroError(
            f"{log.source}: the gyro's motion does not match the video's (speed correlation "
            f"{sync.correlation:.2f}); check the log, or give --gyro-offset and --gyro-axes"
        )
    unbiased = GyroLog(log.times, log.rates - sync.bias, log.source)
    return integrate_rotations(unbiased, times, sync.offset, sync.R_cam_imu), sync
