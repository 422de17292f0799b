"""A gyro log: sample times on the sensor's clock, and body rates in its own axes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


class GyroError(ValueError):
    """A gyro log that cannot be used; the message names the file, line and problem."""


@dataclass(frozen=True)
class GyroLog:
    """times (N,) in seconds on the gyro clock, strictly increasing; rates (N, 3) in
    rad/s, in the sensor's axes; the camera's rolling-shutter readout (s) when the log
    records it."""

    times: NDArray[np.float64]
    rates: NDArray[np.float64]
    source: str = ""
    readout_s: float | None = None

    def __post_init__(self) -> None:
        if self.rates.shape != (len(self.times), 3):
            raise GyroError(f"{self.source}: rates must be (N, 3), got {self.rates.shape}")
        if len(self.times) < 2:
            raise GyroError(f"{self.source}: fewer than two gyro samples")
        steps = np.diff(self.times)
        if np.any(steps <= 0):
            k = int(np.argmax(steps <= 0)) + 1
            raise GyroError(f"{self.source}: time does not increase at sample {k + 1}")

    @property
    def rate_hz(self) -> float:
        """The sensor's sample rate (median interval)."""
        return float(1.0 / np.median(np.diff(self.times)))

    @property
    def span(self) -> tuple[float, float]:
        return float(self.times[0]), float(self.times[-1])
