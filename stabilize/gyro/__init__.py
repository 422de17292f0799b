"""Gyroscope logs: reading them, synchronising them with the video, integrating them
into rotations, and the gyro-driven camera path.

The names below are imported when first used, so reading a log does not compile the
integration kernels.
"""

from __future__ import annotations

from stabilize.lazy import lazy_exports

_EXPORTS = {
    "FORMATS": "stabilize.gyro.readers",
    "READERS": "stabilize.gyro.readers",
    "detect_format": "stabilize.gyro.readers",
    "read_gyro": "stabilize.gyro.readers",
    "read_opencamera": "stabilize.gyro.readers",
    "GyroError": "stabilize.gyro.log",
    "GyroLog": "stabilize.gyro.log",
    "integrate_rotations": "stabilize.gyro.integrate",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports("stabilize.gyro", _EXPORTS)
