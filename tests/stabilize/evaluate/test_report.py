"""The ``--report`` folder: an edited clip's shots in path.csv and the plot, and the 2-D
correction after the turn."""

import csv

import numpy as np
import pytest
from matplotlib.image import imread

from rotation.camera import intrinsics
from stabilize.evaluate.report import write_report
from stabilize.path.plan import plan_path
from stabilize.settings import Settings
from tests.stabilize.helpers import shaky_path


def test_each_frame_of_an_edited_clip_names_its_shot(tmp_path):
    _, O = shaky_path(n=90, shake_deg=0.5)
    R = O[1:] @ np.swapaxes(O[:-1], -1, -2)
    cuts = np.zeros(len(R), bool)
    cuts[[29, 59]] = True  # frames 0-29 | 30-59 | 60-89
    K, size = intrinsics(500.0, (360, 640)), (360, 640)
    planned = plan_path(np.arange(90) / 30, R, np.ones(len(R)), K, size, Settings(), cuts=cuts)
    assert planned.shots == (0, 30, 60)
    write_report(tmp_path / "report", planned, {})
    with open(tmp_path / "report" / "path.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(row["shot"]) for row in rows] == [0] * 30 + [1] * 30 + [2] * 30
    with open(tmp_path / "report" / "rotations.csv") as f:
        pairs = list(csv.DictReader(f))
    assert [int(row["frame"]) for row in pairs if row["cut"] == "1"] == [29, 59]
    assert (tmp_path / "report" / "trajectory.png").stat().st_size > 10_000


def _report_of(tmp_path, residual, motion):
    n = len(residual) + 1
    K, size = intrinsics(500.0, (360, 640)), (360, 640)
    R = np.repeat(np.eye(3)[None], n - 1, 0)
    settings = Settings(motion=motion)
    planned = plan_path(np.arange(n) / 30, R, np.ones(n - 1), K, size, settings, residual=residual)
    write_report(tmp_path / motion, planned, {})
    with open(tmp_path / motion / "path.csv") as f:
        rows = list(csv.DictReader(f))
    names = ("shift_x", "shift_y", "shift_angle", "shift_scale")
    return np.array([[float(row[name]) for name in names] for row in rows])


def test_path_csv_gives_the_2d_correction_in_pixels_degrees_and_scale(tmp_path):
    # The camera does not turn; what the turn leaves jitters frame to frame by a known
    # similarity (dx, dy, a, b), normalised: the correction undoes each step, so its own
    # steps are the jitter's, negated, at f = 500 px.
    sign = (-1.0) ** np.arange(89)
    step = np.c_[0.004 * sign, -0.002 * sign, 0.003 * sign, 0.002 * sign]
    shift = _report_of(tmp_path, step, "similarity")
    moved = np.diff(shift, axis=0)
    assert moved[:, 0] == pytest.approx(-500 * step[:, 0], abs=0.15)  # ±2 px
    assert moved[:, 1] == pytest.approx(-500 * step[:, 1], abs=0.15)  # ∓1 px
    assert moved[:, 2] == pytest.approx(-np.degrees(step[:, 3]), abs=0.02)  # ±0.11°
    assert np.diff(np.log(shift[:, 3])) == pytest.approx(-step[:, 2], abs=3e-4)
    assert (tmp_path / "similarity" / "trajectory.png").stat().st_size > 10_000
    # the turn alone: no 2-D correction, and the plot keeps to the turn's column
    assert np.array_equal(_report_of(tmp_path, step, "rotation"), np.tile([0, 0, 0, 1.0], (90, 1)))
    wide = imread(tmp_path / "similarity" / "trajectory.png").shape[1]
    assert imread(tmp_path / "rotation" / "trajectory.png").shape[1] < 0.6 * wide
