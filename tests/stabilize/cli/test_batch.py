"""``stabilize batch``: its errors, and the options it shares with ``run``."""

import typer
from typer.testing import CliRunner

from stabilize.cli import app
from stabilize.video import probe
from tests.stabilize.helpers import SAMPLE as SAMPLE_DIR

SAMPLE = SAMPLE_DIR / "clip.mp4"


def test_batch_errors():
    result = CliRunner().invoke(app, ["batch", "no-such-folder", "out"])
    assert result.exit_code != 0 and "not a folder" in result.output


def test_an_output_folder_holding_the_input_folder_is_refused(tmp_path):
    # every clip under it was taken for an output and skipped: "no files match '*'"
    (tmp_path / "in" / "sub").mkdir(parents=True)
    (tmp_path / "in" / "sub" / "a.mp4").write_bytes(SAMPLE.read_bytes())
    for src, out in (("in", "in"), ("in/sub", "in")):
        result = CliRunner().invoke(app, ["batch", str(tmp_path / src), str(tmp_path / out)])
        assert result.exit_code == 2 and "the output folder holds the input folder" in result.output


def test_options_that_would_fail_every_clip_are_refused_before_any(tmp_path):
    # each clip failed in turn with the same message, and the batch exited 0
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "a.mp4").write_bytes(SAMPLE.read_bytes())
    (tmp_path / "bad.json").write_text("{not json")
    cases = {
        "no such lens profile": ["--lens", str(tmp_path / "nope.json")],
        "not a Gyroflow lens profile": ["--lens", str(tmp_path / "bad.json")],
        "RAFT weights not found": ["--flow", "raft", "--raft-weights", str(tmp_path / "no.pth")],
        "FFmpeg cannot write libx246 (preset medium) as .mp4": ["--codec", "libx246"],
        "--pix-fmt yuv410p: libx264 does not write it": ["--pix-fmt", "yuv410p"],
    }
    for message, options in cases.items():
        args = ["batch", str(tmp_path / "in"), str(tmp_path / "out"), *options]
        result = CliRunner().invoke(app, args)
        assert result.exit_code == 2 and message in result.output, result.output
    assert not (tmp_path / "out").exists()


def test_more_workers_than_the_machine_runs_at_once_is_said(tmp_path, monkeypatch):
    # a pool of 8 on 2 cores took as long, or was killed for memory, unsaid
    (tmp_path / "in").mkdir()
    for name in "abc":
        (tmp_path / "in" / f"{name}.mp4").write_bytes(SAMPLE.read_bytes())
    monkeypatch.setattr("stabilize.batch.default_workers", lambda: 2)
    monkeypatch.setattr("stabilize.batch.run_batch", lambda *args, **kwargs: [])
    for workers, said in (("8", True), ("2", False)):
        args = ["batch", str(tmp_path / "in"), str(tmp_path / "out"), "--workers", workers]
        result = CliRunner().invoke(app, args)
        assert result.exit_code == 0, result.output
        assert ("notice: --workers 8: this machine runs 2 at once" in result.output) is said


def test_batch_takes_every_option_of_the_single_file_command():
    commands = typer.main.get_command(app).commands
    names = {name: {p.name for p in commands[name].params} for name in ("run", "batch")}
    per_file = {"input_path", "output_path", "report", "overwrite", "as_json"}
    per_clip_gyro = {"gyro_offset", "gyro_axes", "gyro_timestamps"}  # each clip has its own
    per_sequence = {"fps"}  # an image sequence's rate: batch takes a folder's videos
    assert names["run"] - per_file - per_clip_gyro - per_sequence <= names["batch"]


def test_batch_passes_the_options_on(tmp_path):
    src = tmp_path / "in"
    src.mkdir()
    (src / "a.mp4").write_bytes(SAMPLE.read_bytes())
    out = tmp_path / "out"
    args = ["batch", str(src), str(out), "--size", "320x180", "--crop", "none", "-q"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert probe(out / "a.mp4").size == (180, 320)


def test_a_format_with_no_container_names_the_outputs(tmp_path):
    # it named the check's own file: "check.xyz: .xyz names no container"
    src = tmp_path / "in"
    src.mkdir()
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["batch", str(src), str(out), "--format", "xyz"])
    assert result.exit_code == 2
    assert f"error: {out / '*.xyz'}: .xyz names no container FFmpeg writes" in result.output
