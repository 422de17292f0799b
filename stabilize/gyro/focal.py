"""Focal-length calibration against the gyro.

A flow vector of a rotation θ about a lateral axis (pitch x, yaw y) is about f_true·θ
pixels long, and the visual estimate, which assumes f, reads it as θ_vis = θ·f_true/f.
Roll does not depend on f. So the least-squares scale s in

    ω_vis,xy ≈ s · ω_gyro,xy        gives        f_true ≈ s · f,

with the synchronised, unbiased gyro rates in camera axes as the regressor (its noise
is far below the visual estimate's, so s is not diluted). Re-estimating the rotations
with the new f and fitting again converges in one or two rounds.
"""

from __future__ import annotations

import numpy as np

from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.sync import IntervalRates, Sync, visual_rates
from stabilize.motion.track import VisualTrack


def focal_from_gyro(track: VisualTrack, log: GyroLog, sync: Sync, focal: float) -> float:
    """The focal length (pixels) that best explains the gyro's rotations with the flow
    that produced ``track`` at focal length ``focal``."""
    w_vis = visual_rates(track.times, track.rotations)
    w_imu = IntervalRates(log)(sync.clock(track.times), sync.offset, sync.lag(track))
    ok = np.isfinite(w_imu).all(axis=1)
    w_gyro = (w_imu[ok] - sync.bias) @ sync.R_cam_imu.T
    a, b = w_vis[ok, :2].ravel(), w_gyro[:, :2].ravel()
    if b @ b == 0.0:
        raise GyroError(f"{log.source}: no pitch or yaw motion to calibrate the focal length on")
    return float(focal * (a @ b) / (b @ b))
