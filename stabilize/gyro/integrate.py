"""Integrating gyro rates into camera attitude and frame-to-frame rotations (CONVENTIONS.md).

A gyro sample at gyro time g belongs to video time g - offset. In camera axes the rate
is ω_cam = R_cam_imu ω_imu. The attitude G(τ) is the rotation accumulated since the start
of the log, later factors on the left, so that the rotation between two times is

    R(a → b) = G(b) G(a)ᵀ,        G(t_{i+1}) = exp(-[φ_i]×) G(t_i),

the minus because static directions turn opposite to the body. Rates are linear between
samples, so over the part s of a sample interval Δ the angle is integrated exactly:

    φ(s) = ω_i s + (ω_{i+1} - ω_i) s² / (2Δ).

An attitude can be asked for at any time, which is what rolling-shutter correction needs:
each row of a frame has its own capture time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro.log import GyroError, GyroLog

# A camera's own log may start or stop a frame or two off its video: GoPro karma.mp4's
# GPMF gyro starts 53 ms after the first frame. Up to this much, the end sample's rate
# is held (a turn of ω·53 ms, against a frame's shake that changes over ~100 ms).
EDGE_S = 0.1


@numba.njit(cache=True)
def _chain(steps: NDArray) -> NDArray:
    """G_0 = I, G_{i+1} = steps_i G_i (copied element by element: an array assigned to a
    slice makes numba compile its shape-mismatch error's formatting, 0.4 s)."""
    out = np.zeros((len(steps) + 1, 3, 3))
    for r in range(3):
        out[0, r, r] = 1.0
    for i in range(len(steps)):
        G = steps[i] @ out[i]
        for r in range(3):
            for c in range(3):
                out[i + 1, r, c] = G[r, c]
    return out


@dataclass(frozen=True)
class Attitude:
    """G at every gyro sample (gyro clock), with the camera-axis rates it came from."""

    times: NDArray[np.float64]  # (M,) gyro clock
    rates: NDArray[np.float64]  # (M, 3) ω_cam
    G: NDArray[np.float64]  # (M, 3, 3)
    source: str = ""

    def at(self, t: NDArray) -> NDArray[np.float64]:
        """G at gyro-clock times ``t`` (any shape ...), (..., 3, 3)."""
        t = np.asarray(t, dtype=np.float64)
        flat = t.ravel()
        i = np.clip(np.searchsorted(self.times, flat, side="right") - 1, 0, len(self.times) - 2)
        delta = (self.times[i + 1] - self.times[i])[:, None]
        s = (flat - self.times[i])[:, None]
        w0, w1 = self.rates[i], self.rates[i + 1]
        # Inside an interval the rate is linear; beyond the log's ends (up to EDGE_S) the
        # end sample's rate is held. Extrapolating the last interval's slope instead put a
        # 53 ms edge 1.5° off after one sample 0.05 rad/s out at 369 Hz.
        inside = np.clip(s, 0.0, delta)
        phi = w0 * inside + (w1 - w0) * inside**2 / (2.0 * delta)
        phi += w0 * np.minimum(s, 0.0) + w1 * np.maximum(s - delta, 0.0)
        return (so3.exp_so3(-phi) @ self.G[i]).reshape(*t.shape, 3, 3)

    def between(self, a: NDArray, b: NDArray) -> NDArray[np.float64]:
        """R(a → b) = G(b) G(a)ᵀ for gyro-clock times."""
        return self.at(b) @ np.swapaxes(self.at(a), -1, -2)

    def check_covers(self, lo: float, hi: float, offset: float) -> None:
        """Refuse frames at gyro-clock times lo–hi that the log does not reach, beyond
        ``EDGE_S`` at either end (there :meth:`at` holds the end sample's rate)."""
        first, last = self.times[0], self.times[-1]
        if lo < first - EDGE_S or hi > last + EDGE_S:
            raise GyroError(
                f"{self.source}: the gyro log covers {first - offset:.3f}–{last - offset:.3f} s "
                f"of video time, the frames {lo - offset:.3f}–{hi - offset:.3f} s"
            )


def attitude(log: GyroLog, R_cam_imu: NDArray | None = None) -> Attitude:
    """The camera's attitude over the whole log."""
    R_cam_imu = np.eye(3) if R_cam_imu is None else np.asarray(R_cam_imu, dtype=np.float64)
    rates = log.rates @ R_cam_imu.T
    phi = 0.5 * (rates[1:] + rates[:-1]) * np.diff(log.times)[:, None]
    return Attitude(log.times, rates, _chain(so3.exp_so3(-phi)), log.source)


def integrate_rotations(
    log: GyroLog,
    frame_times: NDArray,
    offset: float = 0.0,
    R_cam_imu: NDArray | None = None,
    lag: NDArray | float = 0.0,
) -> NDArray[np.float64]:
    """R_t for each pair of consecutive frame times (video clock), (N-1, 3, 3).

    ``lag`` (per pair, s) shifts both ends of each interval: under a rolling shutter, the
    capture time of the rows a rotation was measured on (readout × their mean height).
    """
    frame_times = np.asarray(frame_times, dtype=np.float64)
    a = frame_times[:-1] + lag + offset
    b = frame_times[1:] + lag + offset
    att = attitude(log, R_cam_imu)
    att.check_covers(float(np.min(a)), float(np.max(b)), offset)
    return att.between(a, b)
