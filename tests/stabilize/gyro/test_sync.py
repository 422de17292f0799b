import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rotation import so3
from stabilize.cli import app
from stabilize.gyro import GyroLog, read_gyro
from stabilize.gyro.sync import signed_permutations, synchronise
from stabilize.rotation_files import read_rotations

SAMPLE = Path(__file__).resolve().parents[3] / "samples" / "street"


@pytest.fixture(scope="module")
def sample():
    meta = json.loads((SAMPLE / "truth.json").read_text())
    truth = read_rotations(SAMPLE / "truth.csv")
    times = np.arange(meta["n_frames"]) / meta["fps"]
    R = so3.exp_so3(np.array([truth[k] for k in range(len(times) - 1)]))
    return meta, times, R, read_gyro(SAMPLE / "gyro.csv")


def test_there_are_24_signed_axis_rotations():
    mats = signed_permutations()
    assert len(mats) == 24
    assert all(np.isclose(np.linalg.det(m), 1.0) for m in mats)


def test_offset_axes_and_bias_are_found_from_the_truth(sample):
    meta, times, R, log = sample
    sync = synchronise(log, times, R)
    assert abs(sync.offset - meta["offset_s"]) < 1e-3
    assert so3.angular_error_deg(sync.R_cam_imu, np.array(meta["R_cam_imu"])) < 0.5
    np.testing.assert_allclose(sync.bias, meta["gyro_bias"], atol=1e-3)
    assert sync.correlation > 0.95


def test_given_offset_and_axes_are_kept(sample):
    _meta, times, R, log = sample
    sync = synchronise(log, times, R, offset=0.3, R_cam_imu=np.eye(3))
    assert sync.offset == 0.3 and np.array_equal(sync.R_cam_imu, np.eye(3))


def test_compare_command_on_a_rendered_clip(tmp_path):
    meta = json.loads((SAMPLE / "truth.json").read_text())
    result = CliRunner().invoke(
        app,
        [
            "compare",
            str(SAMPLE / "clip.mp4"),
            "--gyro",
            str(SAMPLE / "gyro.csv"),
            "--fov",
            "70",
            "-q",
            "--json",
            "--report",
            str(tmp_path),
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    assert abs(summary["offset_s"] - meta["offset_s"]) < 1e-3
    assert summary["axes"] == "YXz" and summary["warning"] is None
    assert summary["aae_deg"] < 0.06 and summary["frames"] == 89
    for name in ("pairs.csv", "summary.json", "rates.png", "error.png", "histogram.png"):
        assert (tmp_path / name).is_file()


def test_a_wrong_log_raises_the_warning(tmp_path, sample):
    _, _, _, log = sample
    rng = np.random.default_rng(0)
    other = GyroLog(log.times, rng.normal(0, 0.3, log.rates.shape), "noise")
    path = tmp_path / "wrong.csv"
    path.write_text(
        "".join(
            f"{x},{y},{z},{round(t * 1e9)}\n"
            for (x, y, z), t in zip(other.rates, other.times, strict=True)
        )
    )
    result = CliRunner().invoke(
        app,
        ["compare", str(SAMPLE / "clip.mp4"), "--gyro", str(path), "--fov", "70", "-q", "--json"],
    )
    assert result.exit_code == 0
    assert "WARNING" in result.output
    start = result.output.index("{")
    assert json.loads(result.output[start:])["warning"]


def test_a_log_that_cannot_cover_the_video_is_an_error(tmp_path):
    path = tmp_path / "short.csv"
    path.write_text("".join(f"0.1,0.2,0.3,{k * 2_500_000}\n" for k in range(100)))
    result = CliRunner().invoke(
        app, ["compare", str(SAMPLE / "clip.mp4"), "--gyro", str(path), "-q"]
    )
    assert result.exit_code != 0 and "does not cover" in result.output
