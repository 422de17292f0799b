"""Reading the gyro log a job names, and checking it, before any work: reading it costs
no numba kernel, so a bad log is reported in a fraction of a second."""

from __future__ import annotations

from dataclasses import replace

from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.readers import read_gyro
from stabilize.settings import Settings


def load_gyro(settings: Settings) -> GyroLog:
    """The log ``settings`` name, read, checked and filtered before any work is done."""
    log = read_gyro(settings.gyro, settings.gyro_format)
    readout_seconds(settings.readout_ms, None)
    return lowpass(log, settings.gyro_lpf) if settings.gyro_lpf else log


def lowpass(log: GyroLog, cutoff_hz: float) -> GyroLog:
    """Zero-phase 2nd-order Butterworth low-pass of the rates (no lag)."""
    nyquist = 0.5 * log.rate_hz
    if not 0 < cutoff_hz < nyquist:
        raise GyroError(f"--gyro-lpf must be between 0 and {nyquist:.0f} Hz, got {cutoff_hz}")
    from scipy.signal import butter, filtfilt  # about 1 s to import: only when filtering

    b, a = butter(2, cutoff_hz, fs=log.rate_hz)
    return replace(log, rates=filtfilt(b, a, log.rates, axis=0))


def readout_seconds(option: float | str | None, from_log: float | None) -> float | None:
    """The readout to use: ``--readout-ms`` (a number, or 'auto': estimate it), else the
    log's own value, else 0 (no rolling-shutter correction). None means 'estimate'."""
    if option is None:
        return from_log or 0.0
    if option == "auto":
        return None
    value = float(option)
    if not 0.0 <= value < 1000.0:
        raise ValueError(f"--readout-ms must be between 0 and 1000 ms, got {option}")
    return value / 1000.0
