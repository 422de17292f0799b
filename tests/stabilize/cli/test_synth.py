"""``stabilize synth``: the clip, its truth and its gyro log on disk."""

import json

from typer.testing import CliRunner

from stabilize.cli import app
from stabilize.video import probe, read_frames


def test_synth_command_writes_clip_truth_and_gyro(tmp_path):
    out = tmp_path / "clip"
    args = ["--seconds", "0.5", "--size", "320x180", "--procedural", "--bob-m", "0.03", "-q"]
    result = CliRunner().invoke(app, ["synth", str(out), *args])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert summary["frames"] == 15
    for name in ("clip.mp4", "truth.csv", "gyro.csv", "timestamps.csv", "truth.json"):
        assert (out / name).is_file(), name
    info = probe(out / "clip.mp4")
    assert info.size == (180, 320) and info.has_audio and info.fps == 30.0
    assert sum(1 for _ in read_frames(out / "clip.mp4", info=info)) == 15
    truth = (out / "truth.csv").read_text().splitlines()
    assert truth[0] == "frame,t,rx,ry,rz,qw,qx,qy,qz,f,cx,cy" and len(truth) == 16
    gyro_line = (out / "gyro.csv").read_text().splitlines()[0].split(",")
    assert len(gyro_line) == 4 and gyro_line[3].isdigit()
    stamps = [int(v) for v in (out / "timestamps.csv").read_text().split()]
    assert len(stamps) == 15 and stamps[0] == 350_000_000  # the 0.35 s default offset
    meta = json.loads((out / "truth.json").read_text())
    assert meta["bob_m"] == 0.03 and meta["sway_m"] == 0.015
    assert not list(out.glob(".*partial*"))  # no temporary files left behind


def test_synth_rejects_a_missing_background(tmp_path):
    result = CliRunner().invoke(app, ["synth", str(tmp_path), "--background", "nope.jpg"])
    assert result.exit_code != 0 and "not found" in result.output


def test_synth_replaces_files_in_its_folder_only_with_overwrite(tmp_path):
    # a folder of one's own clips may hold a clip.mp4: replaced silently before
    (tmp_path / "clip.mp4").write_bytes(b"my holiday")
    args = ["synth", str(tmp_path), "--seconds", "0.2", "--size", "160x90", "--procedural", "-q"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2 and "holds clip.mp4" in result.output
    assert (tmp_path / "clip.mp4").read_bytes() == b"my holiday"
    assert CliRunner().invoke(app, [*args, "--overwrite"]).exit_code == 0
    assert probe(tmp_path / "clip.mp4").size == (90, 160)
