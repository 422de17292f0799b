"""Rolling shutter from the video alone: the readout time, and the camera's continuous
attitude that dates every row (:mod:`.attitude`, :mod:`.readout`).

The gyro mode dates the rows from the gyro (:mod:`stabilize.gyro.rolling_shutter`); here
the same per-row turns come from the rotations pass 1 measured on horizontal bands of
each frame, each band seen at its own capture time.
"""

from __future__ import annotations

from stabilize.lazy import lazy_exports

_EXPORTS = {
    "Readout": "stabilize.shutter.readout",
    "estimate_readout": "stabilize.shutter.readout",
    "readout_for": "stabilize.shutter.readout",
    "visual_attitude": "stabilize.shutter.attitude",
    "visual_rolling_shutter": "stabilize.shutter.rows",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports("stabilize.shutter", _EXPORTS)
