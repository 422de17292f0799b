"""Writing the visual estimate as a Gyroflow ``.gcsv`` of angular rates.

Each frame interval's mean rate ω = -log(R_t)/Δt (camera axes of CONVENTIONS.md: x
right, y down, z forward) is written at the interval's midpoint, in rad/s with
``tscale`` 0.001 (milliseconds). ``orientation`` is ``XYZ``: Gyroflow's own axis setting
can remap it if its convention for a clip differs.
"""

from __future__ import annotations

from pathlib import Path
from typing import TextIO

from numpy.typing import NDArray

from stabilize.gyro.sync import visual_rates


def write_gcsv(path: str | Path | TextIO, times: NDArray, R: NDArray) -> None:
    """The visual rates as a Gyroflow .gcsv log, into a file or an open text stream."""
    rates = visual_rates(times, R)
    mid_ms = 1000.0 * 0.5 * (times[1:] + times[:-1])
    lines = [
        "GYROFLOW IMU LOG",
        "version,1.3",
        "id,hough-stabilize-visual",
        "orientation,XYZ",
        "note,angular rates estimated from optical flow (Hough transform on SO(3))",
        "tscale,0.001",
        "gscale,1.0",
        "t,gx,gy,gz",
    ]
    lines += [
        f"{t:.3f},{x:.9f},{y:.9f},{z:.9f}" for t, (x, y, z) in zip(mid_ms, rates, strict=True)
    ]
    text = "\n".join(lines) + "\n"
    if isinstance(path, str | Path):
        Path(path).write_text(text)
    else:
        path.write(text)


__all__ = ["write_gcsv"]
