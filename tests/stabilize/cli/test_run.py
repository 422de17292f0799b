"""``stabilize run`` (and ``stabilize IN OUT``): outputs, reports, and bad input."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from stabilize.cli import app, main
from stabilize.video import ffmpeg_exe, frame_times, probe, read_frames
from tests.stabilize.conftest import render

RUNNER = CliRunner()


def test_main_job_is_the_default_command(shaky, tmp_path, monkeypatch, capsys):
    out = tmp_path / "cli.mp4"
    monkeypatch.setattr(
        "sys.argv",
        ["stabilize", str(shaky), str(out), "-q", "--json", "--report", str(tmp_path / "rep")],
    )
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 0
    assert json.loads(capsys.readouterr().out)["frames"] == 60
    for name in ("rotations.csv", "path.csv", "trajectory.png", "summary.json"):
        assert (tmp_path / "rep" / name).is_file()
    # An existing output is refused without --overwrite, and left alone.
    before = out.read_bytes()
    result = RUNNER.invoke(app, ["run", str(shaky), str(out), "-q"])
    assert result.exit_code != 0 and "exists" in result.output
    assert out.read_bytes() == before


def bad_inputs(tmp_path: Path, shaky: Path) -> dict[str, Path]:
    text = tmp_path / "notes.mp4"
    text.write_text("this is not a video\n")
    truncated = tmp_path / "truncated.mp4"
    data = shaky.read_bytes()
    truncated.write_bytes(data[: len(data) // 3])
    return {"missing": tmp_path / "nope.mp4", "not a video": text, "truncated": truncated}


@pytest.mark.parametrize("case", ["missing", "not a video", "truncated"])
def test_bad_input_is_one_clear_line_and_nothing_is_written(shaky, tmp_path, case):
    source = bad_inputs(tmp_path, shaky)[case]
    before = source.read_bytes() if source.exists() else None
    out = tmp_path / "out.mp4"
    result = RUNNER.invoke(app, ["run", str(source), str(out), "-q"])
    assert result.exit_code != 0
    assert (
        result.output.strip().startswith("error:") and len(result.output.strip().splitlines()) == 1
    )
    assert not out.exists() and not list(tmp_path.glob(".out*"))
    if before is not None:
        assert source.read_bytes() == before


def test_output_equal_to_the_input_is_refused(tmp_path):
    clip = render(tmp_path / "two", seed=2, seconds=1 / 30 * 2)
    shutil.copy(clip, tmp_path / "copy.mp4")
    result = RUNNER.invoke(app, ["run", str(clip), str(clip), "-q"])
    assert result.exit_code != 0 and "is the input" in result.output
    assert (tmp_path / "copy.mp4").read_bytes() == clip.read_bytes()


def test_standard_output_is_refused_as_the_output_by_name(shaky, tmp_path, monkeypatch):
    # it read "-: no suffix names its container ... (-.mp4)"
    monkeypatch.chdir(tmp_path)
    result = RUNNER.invoke(app, ["run", str(shaky), "-"])
    assert result.exit_code == 2 and "OUT '-': a video is written to a file" in result.output
    assert list(tmp_path.iterdir()) == []


def test_one_and_zero_frame_videos(shaky, tmp_path):
    one, silent = tmp_path / "one.mp4", tmp_path / "audio_only.m4a"
    ff = [ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-y"]
    subprocess.run([*ff, "-i", str(shaky), "-frames:v", "1", "-an", str(one)], check=True)
    subprocess.run([*ff, "-f", "lavfi", "-i", "sine=duration=1", str(silent)], check=True)
    result = RUNNER.invoke(app, ["run", str(one), str(tmp_path / "o1.mp4"), "-q"])
    assert result.exit_code != 0 and "1 frame" in result.output
    result = RUNNER.invoke(app, ["run", str(silent), str(tmp_path / "o2.mp4"), "-q"])
    assert result.exit_code != 0 and "has no video stream, only audio" in result.output
    assert not (tmp_path / "o1.mp4").exists() and not (tmp_path / "o2.mp4").exists()


def test_side_by_side_preview(shaky, tmp_path):
    out = tmp_path / "preview.mp4"
    result = RUNNER.invoke(app, ["run", str(shaky), str(out), "-q", "--preview", "side-by-side"])
    assert result.exit_code == 0, result.output
    assert probe(out).size == (180, 640)
    left = next(read_frames(out))[:, :320].astype(float)
    assert np.abs(left - next(read_frames(shaky)).astype(float)).mean() < 3


def test_output_size(shaky, tmp_path):
    out = tmp_path / "small.mp4"
    result = RUNNER.invoke(app, ["run", str(shaky), str(out), "--size", "160x90", "-q"])
    assert result.exit_code == 0, result.output
    assert probe(out).size == (90, 160) and len(frame_times(out)) == 60
    bad = RUNNER.invoke(app, ["run", str(shaky), str(tmp_path / "x.mp4"), "--size", "big"])
    assert bad.exit_code != 0 and "WIDTHxHEIGHT" in bad.output
    # another shape was stretched to: a phone's upright clip to 1280x720
    tall = RUNNER.invoke(app, ["run", str(shaky), str(tmp_path / "x.mp4"), "--size", "90x160"])
    assert tall.exit_code == 2 and "would stretch the 320x180 picture: give its shape, e.g. " \
        "90x50 or 284x160" in tall.output  # fmt: skip
    assert not (tmp_path / "x.mp4").exists()
