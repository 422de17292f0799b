"""The ``--report`` folder: an edited clip's shots in path.csv and the plot."""

import csv

import numpy as np

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
