"""Rolling shutter: each row of a frame has its own capture time, and so its own attitude.

Row y of frame k (height H, readout r) is captured at τ_k(y) = t_k + δ + r·(y + ½)/H on
the gyro clock. The frame as a whole is given the attitude of its middle row,
τ_k = t_k + δ + r/2, which the path is smoothed on; what is left per row is the turn

    D_k(y) = G(τ_k(y)) G(τ_k)ᵀ,

which the warp undoes row by row (:mod:`stabilize.warp.rolling`). The gyro is sampled at its
full rate, so shake faster than the frame rate is corrected too.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.gyro.integrate import Attitude
from stabilize.warp.rolling import KNOTS, RollingShutter


def frame_rotations(
    att: Attitude, times: NDArray, offset: float, readout: float
) -> NDArray[np.float64]:
    """R_t between the middle rows of consecutive frames, (N-1, 3, 3)."""
    mid = np.asarray(times) + offset + 0.5 * readout
    att.check_covers(float(mid[0]), float(mid[-1]), offset)
    return att.between(mid[:-1], mid[1:])


def row_turns(
    att: Attitude, times: NDArray, offset: float, readout: float, height: int, knots: int = KNOTS
) -> RollingShutter:
    """D_k(y) at ``knots`` rows from the top to the bottom edge of every frame."""
    rows = np.linspace(-0.5, height - 0.5, knots)
    start = np.asarray(times) + offset
    at_rows = start[:, None] + readout * (rows[None, :] + 0.5) / height
    att.check_covers(float(at_rows.min()), float(at_rows.max()), offset)
    G_rows = att.at(at_rows)
    G_mid = att.at(start + 0.5 * readout)
    return RollingShutter(G_rows @ np.swapaxes(G_mid, -1, -2)[:, None], rows)
