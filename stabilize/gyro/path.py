"""The gyro as the source of the path: R_t from a log, synchronised against the visual
estimate, and the per-row turns of a rolling shutter when the readout is known or
estimated."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.gyro.readers import read_gyro
from stabilize.gyro.rolling_shutter import frame_rotations, row_turns
from stabilize.gyro.source import gyro_rotations, lowpass
from stabilize.gyro.sync import SyncOptions
from stabilize.motion.track import VisualTrack
from stabilize.settings import Settings
from stabilize.warp.lens import Lens
from stabilize.warp.rolling import RollingShutter


def gyro_path(
    settings: Settings, track: VisualTrack, height: int, lens: Lens | None = None
) -> tuple[NDArray, RollingShutter | None, dict]:
    """(R_t, the rolling-shutter turns or None, a summary) from the gyro log named in
    ``settings``, synchronised against the visual ``track``."""
    log = read_gyro(settings.gyro, settings.gyro_format)
    if settings.gyro_lpf:
        log = lowpass(log, settings.gyro_lpf)
    axes = None if settings.gyro_axes is None else np.array(settings.gyro_axes, dtype=float)
    readout = readout_seconds(settings.readout_ms, log.readout_s or (lens and lens.readout_s))
    options = SyncOptions(settings.gyro_offset, axes, readout, settings.gyro_drift)
    att, sync = gyro_rotations(log, track, options)
    clock = sync.clock(track.times)
    R = frame_rotations(att, clock, sync.offset, sync.readout)
    rolling = row_turns(att, clock, sync.offset, sync.readout, height) if sync.readout else None
    return (
        R,
        rolling,
        {
            "log": str(settings.gyro),
            "offset_s": sync.offset,
            "R_cam_imu": sync.R_cam_imu.tolist(),
            "speed_correlation": sync.correlation,
            "rate_hz": log.rate_hz,
            "readout_ms": 1000.0 * sync.readout,
            "readout_estimated": sync.readout_estimated,
        },
    )


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
