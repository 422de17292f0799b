"""Rotation files: one row per frame pair, ``frame,t,rx,ry,rz[,...]`` (R_t as a rotation
vector in radians, CONVENTIONS.md). ``stabilize rotations`` writes them, with ``support``
and ``cut`` columns; ``stabilize synth``'s ``truth.csv`` has the same leading columns."""

from __future__ import annotations

import csv
from contextlib import nullcontext
from pathlib import Path
from typing import TextIO

import numpy as np
from numpy.typing import NDArray

from rotation import so3

COLUMNS = ("frame", "t", "rx", "ry", "rz")


def read_rotations(path: str | Path) -> dict[int, NDArray[np.float64]]:
    """{frame: rotation vector} for every row that has one."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such rotations file")
    out = {}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path}: missing column(s) {', '.join(missing)}")
        for line, row in enumerate(reader, start=2):
            if not row["rx"]:
                continue  # the last frame of a truth file has no pair
            try:
                out[int(row["frame"])] = np.array([float(row[k]) for k in ("rx", "ry", "rz")])
            except ValueError:
                raise ValueError(f"{path}:{line}: not a number") from None
    return out


def write_rotations(path: str | Path | TextIO, times, rotvecs, support, cuts=None) -> None:
    """``frame,t,rx,ry,rz,support,cut`` for each pair (frame k → k+1), into a file or an
    open text stream (standard output); ``cut`` 1 where the pair is a change of shot
    (:mod:`stabilize.motion.cuts`: its rotation is no camera's turn), else 0."""
    cuts = np.zeros(len(times), bool) if cuts is None else np.asarray(cuts, bool)
    opened = open(path, "w", newline="") if isinstance(path, str | Path) else nullcontext(path)
    with opened as f:
        writer = csv.writer(f)
        writer.writerow([*COLUMNS, "support", "cut"])
        rows = zip(times, rotvecs, support, cuts, strict=True)
        for k, (t, rv, s, cut) in enumerate(rows):
            writer.writerow([k, f"{t:.6f}", *(f"{v:.9g}" for v in rv), f"{s:.4f}", int(cut)])


def angular_errors(estimate: dict, truth: dict) -> NDArray[np.float64]:
    """θ(R̂ Rᵀ) in degrees for the frames present in both."""
    common = sorted(set(estimate) & set(truth))
    if not common:
        raise ValueError("the rotations and the truth share no frame")
    R_hat = so3.exp_so3(np.array([estimate[k] for k in common]))
    R = so3.exp_so3(np.array([truth[k] for k in common]))
    return so3.angular_error_deg(R_hat, R)
