"""Readers for gyro log formats. Each gives a :class:`GyroLog` in rad/s and seconds."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stabilize.gyro.log import GyroError, GyroLog


def _rows(path: Path, n_fields: int, *, skip_header: bool = False) -> list[list[float]]:
    """Numeric CSV rows, or a GyroError naming the first bad line."""
    if not path.is_file():
        raise GyroError(f"{path}: no such gyro log")
    rows = []
    with open(path, errors="replace") as f:
        for number, line in enumerate(f, start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            fields = line.split(",")
            if len(fields) != n_fields:
                if skip_header and not rows:
                    continue
                raise GyroError(
                    f"{path}:{number}: expected {n_fields} comma-separated fields, "
                    f"got {len(fields)}"
                )
            try:
                rows.append([float(v) for v in fields])
            except ValueError:
                if skip_header and not rows:
                    continue
                raise GyroError(f"{path}:{number}: not a number in {line!r}") from None
    if not rows:
        raise GyroError(f"{path}: no gyro samples")
    return rows


def read_opencamera(path: str | Path) -> GyroLog:
    """OpenCamera Sensors: ``x,y,z,t_ns`` per line, rad/s, no header."""
    path = Path(path)
    data = np.array(_rows(path, 4))
    return GyroLog(data[:, 3] * 1e-9, data[:, :3], str(path))


def read_frame_timestamps_ns(path: str | Path) -> np.ndarray:
    """OpenCamera Sensors' frame timestamps: one integer (ns) per line → seconds."""
    path = Path(path)
    data = np.array(_rows(path, 1))[:, 0]
    if np.any(np.diff(data) <= 0):
        raise GyroError(f"{path}: frame times do not increase")
    return data * 1e-9
