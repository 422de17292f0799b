"""The gyro as the source of the camera path: synchronising and integrating."""

from __future__ import annotations

from dataclasses import replace

from stabilize.gyro.integrate import Attitude, attitude
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.sync import MIN_CORRELATION, Sync, SyncOptions
from stabilize.motion.track import VisualTrack


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
