"""Integrating gyro rates into frame-to-frame rotations (CONVENTIONS.md).

A gyro sample at gyro time g belongs to video time g - offset. In camera axes the rate
is ω_cam = R_cam_imu ω_imu, and over the interval between two frame times

    R_t = Π exp(-[ω_cam(τ) dτ]×)      (later factors on the left),

the minus because static directions turn opposite to the body. Rates are interpolated
linearly between samples and integrated with the midpoint rule over every piece
between consecutive sample and frame times, so the ends are interpolated exactly.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro.log import GyroError, GyroLog


def rates_at(log: GyroLog, t_video: NDArray, offset: float, R_cam_imu: NDArray) -> NDArray:
    """ω_cam (len(t), 3) at video times, linearly interpolated."""
    g = np.asarray(t_video) + offset
    imu = np.stack([np.interp(g, log.times, log.rates[:, a]) for a in range(3)], axis=-1)
    return imu @ np.asarray(R_cam_imu).T


def integrate_rotations(
    log: GyroLog,
    frame_times: NDArray,
    offset: float = 0.0,
    R_cam_imu: NDArray | None = None,
) -> NDArray[np.float64]:
    """R_t for each pair of consecutive frame times (video clock), (N-1, 3, 3)."""
    frame_times = np.asarray(frame_times, dtype=np.float64)
    R_cam_imu = np.eye(3) if R_cam_imu is None else np.asarray(R_cam_imu, dtype=np.float64)
    first, last = log.span
    if frame_times[0] + offset < first or frame_times[-1] + offset > last:
        raise GyroError(
            f"{log.source}: the gyro log covers {first - offset:.3f}–{last - offset:.3f} s of "
            f"video time, the frames {frame_times[0]:.3f}–{frame_times[-1]:.3f} s"
        )
    inside = (log.times - offset > frame_times[0]) & (log.times - offset < frame_times[-1])
    knots = np.union1d(frame_times, log.times[inside] - offset)
    mids = 0.5 * (knots[1:] + knots[:-1])
    steps = so3.exp_so3(-rates_at(log, mids, offset, R_cam_imu) * np.diff(knots)[:, None])
    # Which frame interval each piece belongs to.
    owner = np.searchsorted(frame_times, mids, side="right") - 1
    out = np.tile(np.eye(3), (len(frame_times) - 1, 1, 1))
    for k, E in zip(owner, steps, strict=True):
        out[k] = E @ out[k]
    return out
