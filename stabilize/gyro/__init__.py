"""Gyroscope logs: reading them, and integrating them into frame-to-frame rotations."""

from stabilize.gyro.integrate import integrate_rotations
from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.readers import read_opencamera

__all__ = ["GyroError", "GyroLog", "integrate_rotations", "read_opencamera"]
