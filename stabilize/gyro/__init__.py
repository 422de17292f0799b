"""Gyroscope logs: reading them, and integrating them into frame-to-frame rotations."""

from stabilize.gyro.integrate import integrate_rotations
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.readers import FORMATS, detect_format, read_gyro, read_opencamera

__all__ = [
    "FORMATS",
    "GyroError",
    "GyroLog",
    "detect_format",
    "integrate_rotations",
    "read_gyro",
    "read_opencamera",
]
