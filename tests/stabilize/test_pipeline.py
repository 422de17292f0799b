"""End to end on short rendered clips: timing, audio, borders, zoom, and bad input."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rotation import so3
from stabilize.cli import app, main
from stabilize.ffmpeg_tools import ffmpeg_exe
from stabilize.pipeline import Settings, stabilize_video
from stabilize.synth import SynthOptions, render_clip, trajectory
from stabilize.video_reader import frame_times, probe, read_frames

RUNNER = CliRunner()


def render(folder: Path, **options) -> Path:
    opts = SynthOptions(size=(180, 320), **{"seconds": 2.0, **options})
    render_clip(folder, opts)
    return folder / "clip.mp4"


@pytest.fixture(scope="module")
def shaky(tmp_path_factory) -> Path:
    return render(tmp_path_factory.mktemp("shaky"), seed=11, shake_deg=1.5, crowd=4)


@pytest.fixture(scope="module")
def stabilised(shaky, tmp_path_factory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("out") / "steady.mp4"
    summary, planned = stabilize_video(shaky, out, Settings(fov=70.0))
    return out, summary, planned


def test_frames_timestamps_and_audio_are_kept(shaky, stabilised):
    out, summary, _ = stabilised
    a, b = probe(shaky), probe(out)
    assert b.size == a.size and b.has_audio and a.has_audio
    np.testing.assert_allclose(frame_times(out), frame_times(shaky), atol=1e-3)
    assert summary["frames"] == len(frame_times(shaky)) == 60


def test_variable_frame_rate_timestamps_are_kept(shaky, tmp_path):
    vfr = tmp_path / "vfr.mp4"
    jitter = ["-vf", "setpts=(N+0.4*mod(N\\,3))/30/TB", "-enc_time_base:v", "1:90000"]
    subprocess.run(
        [
            ffmpeg_exe(),
            "-v",
            "error",
            "-i",
            str(shaky),
            *jitter,
            "-fps_mode",
            "passthrough",
            "-c:a",
            "copy",
            str(vfr),
        ],
        check=True,
    )
    times = frame_times(vfr)
    assert len(times) == 60 and np.ptp(np.diff(times)) > 0.01  # really variable
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(vfr, out, Settings(fov=70.0))
    np.testing.assert_allclose(frame_times(out), times, atol=1e-3)
    assert summary["frames"] == 60 and probe(out).has_audio
    assert not list(tmp_path.glob("*.cfr.mp4"))  # the intermediate file is gone


def test_no_black_border_in_auto_crop(stabilised):
    out, _, _ = stabilised
    for frame in read_frames(out):
        edges = np.concatenate([frame[0], frame[-1], frame[:, 0], frame[:, -1]])
        assert np.mean(edges.max(axis=1) < 8) < 0.01  # no black pixels along the borders


def test_the_residual_jitter_is_a_fraction_of_the_input(shaky, stabilised):
    _, _, planned = stabilised
    opts = json.loads((shaky.parent / "truth.json").read_text())
    motion = SynthOptions(
        seed=opts["seed"],
        seconds=opts["seconds"],
        shake_deg=opts["shake_deg"],
        size=tuple(opts["size"]),
    ).motion
    O_true = trajectory.orientation(motion, planned.times)
    C = planned.smooth @ np.swapaxes(planned.raw, -1, -2)
    out = C @ O_true  # the output camera's true orientation

    def jitter(O):
        return np.std(
            np.diff(np.degrees(so3.log_so3(O[1:] @ np.swapaxes(O[:-1], -1, -2))), 2, axis=0)
        )

    assert jitter(out) < 0.25 * jitter(O_true)


def test_zoom_limit_is_respected_and_dynamic_crop_has_no_border(shaky, tmp_path):
    out = tmp_path / "dyn.mp4"
    summary, planned = stabilize_video(
        shaky, out, Settings(fov=70.0, crop="dynamic", max_zoom=1.08)
    )
    assert planned.zoom.max() <= 1.08 + 1e-6
    assert summary["zoom"] <= 1.08 + 1e-6
    for frame in read_frames(out):
        edges = np.concatenate([frame[0], frame[-1], frame[:, 0], frame[:, -1]])
        assert np.mean(edges.max(axis=1) < 8) < 0.01


def test_a_static_clip_comes_out_unchanged(tmp_path):
    clip = render(tmp_path / "static", seed=1, shake_deg=0.0, pan_deg=0.0, walk=0.0, crowd=0)
    out = tmp_path / "out.mp4"
    summary, _planned = stabilize_video(clip, out, Settings(fov=70.0))
    assert summary["zoom"] < 1.01
    a = np.stack(list(read_frames(clip))).astype(float)
    b = np.stack(list(read_frames(out))).astype(float)
    assert np.abs(a - b).mean() < 2.5  # compression only


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


def test_rotations_command(shaky, tmp_path):
    out = tmp_path / "rot.csv"
    result = RUNNER.invoke(app, ["rotations", str(shaky), "-o", str(out), "-q", "--fov", "70"])
    assert result.exit_code == 0, result.output
    lines = out.read_text().splitlines()
    assert lines[0] == "frame,t,rx,ry,rz,support" and len(lines) == 60


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


def test_one_and_zero_frame_videos(shaky, tmp_path):
    one, silent = tmp_path / "one.mp4", tmp_path / "audio_only.m4a"
    ff = [ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-y"]
    subprocess.run([*ff, "-i", str(shaky), "-frames:v", "1", "-an", str(one)], check=True)
    subprocess.run([*ff, "-f", "lavfi", "-i", "sine=duration=1", str(silent)], check=True)
    result = RUNNER.invoke(app, ["run", str(one), str(tmp_path / "o1.mp4"), "-q"])
    assert result.exit_code != 0 and "1 frame" in result.output
    result = RUNNER.invoke(app, ["run", str(silent), str(tmp_path / "o2.mp4"), "-q"])
    assert result.exit_code != 0 and "not a video" in result.output
    assert not (tmp_path / "o1.mp4").exists() and not (tmp_path / "o2.mp4").exists()


def test_portrait_rotation_metadata_is_honoured(shaky, tmp_path):
    rotated = tmp_path / "portrait.mp4"
    cmd = [
        ffmpeg_exe(),
        "-hide_banner",
        "-loglevel",
        "error",
        "-display_rotation",
        "90",
        "-i",
        str(shaky),
        "-c",
        "copy",
        str(rotated),
    ]
    subprocess.run(cmd, check=True)
    info = probe(rotated)
    assert info.rotation in (90, 270) and info.size == (320, 180)  # displayed upright
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(rotated, out, Settings(fov=50.0))
    result = probe(out)
    assert result.size == (320, 180) and result.rotation == 0
    assert summary["frames"] == 60


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


def test_a_10_bit_source_stays_10_bit(shaky, tmp_path):
    ten = tmp_path / "ten.mp4"
    encode = ["-c:v", "libx264", "-pix_fmt", "yuv420p10le", "-c:a", "copy"]
    subprocess.run([ffmpeg_exe(), "-v", "error", "-i", str(shaky), *encode, str(ten)], check=True)
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(ten, out, Settings(fov=70.0))
    assert probe(out).pix_fmt.startswith("yuv420p10") and summary["frames"] == 60
    frames = list(read_frames(out))
    assert len(frames) == 60 and min(f.mean() for f in frames) > 20  # content, not black
