"""The per-row turns of a rolling-shutter frame from the visual attitude, in the form
the gyro mode hands the planner (:mod:`stabilize.gyro.rolling_shutter`): the same
integration of the same kind of rates, so the two modes correct rows alike."""

from __future__ import annotations

from numpy.typing import NDArray

from stabilize.gyro.rolling_shutter import frame_rotations, row_turns
from stabilize.shutter.attitude import Spline, visual_attitude
from stabilize.warp.rolling import RollingShutter


def visual_rolling_shutter(
    spline: Spline, times: NDArray, readout: float, height: int
) -> tuple[NDArray, RollingShutter]:
    """(R_t between the middle rows of consecutive frames (N-1, 3, 3), the turns D_k(y)
    of every frame's rows against its middle row) of the attitude fitted at ``readout``
    (s), for frames ``height`` px high."""
    att = visual_attitude(spline, times)
    return frame_rotations(att, times, 0.0, readout), row_turns(att, times, 0.0, readout, height)
