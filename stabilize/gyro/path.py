"""The gyro as the source of the path: R_t from a log, synchronised against the visual
estimate, and the per-row turns of a rolling shutter when the readout is known or
estimated."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from stabilize.gyro.load import starting_readout
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.rolling_shutter import frame_rotations, row_turns
from stabilize.gyro.source import gyro_rotations
from stabilize.gyro.sync import IMPOSSIBLE_SCALE, SyncOptions, motion_scale
from stabilize.motion.track import VisualTrack
from stabilize.settings import Settings
from stabilize.warp.lens import Lens
from stabilize.warp.rolling import RollingShutter


def gyro_path(
    settings: Settings,
    log: GyroLog,
    track: VisualTrack,
    height: int,
    lens: Lens | None = None,
    stamps: NDArray | None = None,
) -> tuple[NDArray, RollingShutter | None, dict]:
    """(R_t, the rolling-shutter turns or None, a summary) from a gyro ``log``
    (:func:`stabilize.gyro.load.load_gyro`), synchronised against the visual ``track``.
    With ``stamps`` (``gyro_timestamps``' frame times) the frames are dated on the
    gyro's clock."""
    if stamps is not None:
        # (a container may list one frame more than decodes: the track has the decoded)
        track = replace(track, times=np.asarray(stamps[: len(track.times)], dtype=np.float64))
    axes = None if settings.gyro_axes is None else np.array(settings.gyro_axes, dtype=float)
    readout, source = starting_readout(settings.readout_ms, log.readout_s, lens and lens.readout_s)
    options = SyncOptions(
        settings.gyro_offset, axes, readout, settings.gyro_drift, settings.gyro_search, source
    )
    att, sync = gyro_rotations(log, track, options)
    clock = sync.clock(track.times)
    R = frame_rotations(att, clock, sync.offset, sync.readout)
    scale = motion_scale(track.rotations, R)
    if not IMPOSSIBLE_SCALE[0] < scale < IMPOSSIBLE_SCALE[1]:
        raise GyroError(
            f"{log.source}: the video turns {scale:.3g} times as far as this gyro says, "
            "which no focal length explains: a log in another unit (degrees read as "
            "radians?), or another clip's log"
        )
    rolling = row_turns(att, clock, sync.offset, sync.readout, height) if sync.readout else None
    return (
        R,
        rolling,
        {
            "log": str(settings.gyro),
            "offset_s": sync.offset,
            "R_cam_imu": sync.R_cam_imu.tolist(),
            "speed_correlation": sync.correlation,
            "motion_scale": scale,  # the video's turn over the gyro's: about 1
            "rate_hz": log.rate_hz,
            "readout_ms": 1000.0 * sync.readout,
            "readout_estimated": sync.readout_estimated,
            "readout_source": sync.readout_source,
            "searched_whole_log": sync.searched_whole_log,
        },
    )
