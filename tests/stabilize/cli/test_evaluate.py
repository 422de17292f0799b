"""``stabilize evaluate``: the metrics of two clips, as text and JSON."""

import json

import pytest
from typer.testing import CliRunner

from stabilize.cli import app

SMALL = {"size": (180, 320), "seconds": 3.0, "fps": 30.0, "crowd": 0, "seed": 3, "walk": 0}


@pytest.fixture(scope="module")
def sample(tmp_path_factory) -> str:
    """The sample clip at 320x180: evaluate reads both clips' flow, 4x faster than at
    its 640x360."""
    import subprocess

    from stabilize.video import ffmpeg_exe

    out = tmp_path_factory.mktemp("small") / "clip.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", "samples/street/clip.mp4", "-vf", "scale=320:180"]
    subprocess.run([*cmd, str(out)], check=True)
    return str(out)


def test_evaluate_command(sample):
    truth = "samples/street/truth.csv"
    result = CliRunner().invoke(app, ["evaluate", sample, sample, "--truth", truth,
                                      "--rotations", truth, "--json"])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert '"aae_deg": 0.0' in result.output
    metrics = json.loads(result.stdout)["stabilised"]  # (the progress bar is on stderr)
    parts = metrics["shake_components_px"]  # x, y, roll, zoom: their length is the shake
    assert len(parts) == 4 and sum(x * x for x in parts) ** 0.5 == pytest.approx(
        metrics["residual_shake_px"]
    )
    bad = CliRunner().invoke(app, ["evaluate", "README.md", sample])
    assert bad.exit_code != 0 and "not a video" in bad.output


@pytest.fixture(scope="module")
def second(sample, tmp_path_factory) -> str:
    """The small sample's first second: --spread registers each clip four times."""
    import subprocess

    from stabilize.video import ffmpeg_exe

    out = tmp_path_factory.mktemp("second") / "clip.mp4"
    subprocess.run([ffmpeg_exe(), "-v", "error", "-i", sample, "-t", "1", str(out)], check=True)
    return str(out)


def test_evaluate_reads_the_shake_mirrored_too(second):
    result = CliRunner().invoke(app, ["evaluate", second, second, "--spread", "--json", "-q"])
    assert result.exit_code == 0, result.output
    metrics = json.loads(result.stdout)
    for clip in ("original", "stabilised"):
        spread = metrics[clip]["residual_shake_spread_px"]
        assert spread["readings"][0] == metrics[clip]["residual_shake_px"]
        assert len(spread["readings"]) == 4
        assert spread["min"] <= spread["mean"] <= spread["max"]
    # the same clip twice: the same four readings (approx compares flat values alone)
    same, again = (metrics[clip]["residual_shake_spread_px"] for clip in ("original", "stabilised"))
    assert same["readings"] == pytest.approx(again["readings"])
    assert [same[k] for k in ("min", "mean", "max")] == pytest.approx(
        [again[k] for k in ("min", "mean", "max")]
    )
    text = CliRunner().invoke(app, ["evaluate", second, second, "--spread", "-q"])
    assert text.exit_code == 0 and "residual shake mirrored (px): original" in text.stdout


def test_evaluate_reads_the_spread_at_more_sizes(second, monkeypatch):
    # two of the sizes, not five: the wiring is the same, and the five took 27 s of the
    # suite (20 readings of each clip; the sizes themselves are the metrics tests')
    import stabilize.evaluate.metrics as metrics_module

    monkeypatch.setattr(metrics_module, "SPREAD_SIZES", (576, 640))
    args = ["evaluate", second, second, "--spread", "--sizes", "--json", "-q"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    metrics = json.loads(result.stdout)["stabilised"]
    spread = metrics["residual_shake_spread_px"]
    assert len(spread["readings"]) == 8  # four mirrorings at each of the two sizes
    assert spread["readings"][0] == metrics["residual_shake_px"]
    assert spread["min"] <= spread["mean"] <= spread["max"]
    alone = CliRunner().invoke(app, ["evaluate", second, second, "--sizes"])
    assert alone.exit_code == 2 and "give --spread too" in alone.output


def test_evaluate_draws_the_shake(sample, tmp_path):
    png = tmp_path / "shake.png"
    result = CliRunner().invoke(app, ["evaluate", sample, sample, "--plot", str(png), "-q"])
    assert result.exit_code == 0, result.output
    assert "x, y, roll, zoom (px)" in result.output  # the table, as without --plot
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    (tmp_path / "folder.png").mkdir()  # an internal error once the work was done, before
    wrongs = {"shake.txt": "give a .png file", "no/shake.png": "no such folder"}
    wrongs["folder.png"] = "is a folder"
    for wrong, why in wrongs.items():
        bad = CliRunner().invoke(app, ["evaluate", sample, sample, "--plot", str(tmp_path / wrong)])
        assert bad.exit_code == 2 and why in bad.output


def test_evaluate_reads_an_image_sequence_at_the_rate_given(tmp_path):
    import subprocess

    from stabilize.video import ffmpeg_exe

    frames = tmp_path / "f%03d.png"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", "samples/street/clip.mp4", "-frames:v", "24"]
    cmd += ["-vf", "scale=320:180"]  # 4x faster to read than at 640x360
    subprocess.run([*cmd, "-start_number", "50", str(frames)], check=True)
    shake = {}
    for fps in ("10", "60"):  # the high-pass keeps 0.5 s: 5 frames, or 30
        args = ["evaluate", str(frames), str(frames), "--fps", fps, "--json", "-q"]
        result = CliRunner().invoke(app, args)
        assert result.exit_code == 0, result.output
        shake[fps] = json.loads(result.stdout)["original"]["residual_shake_px"]
    assert shake["10"] < shake["60"]


def test_the_plot_never_replaces_an_input(tmp_path):
    # --plot f001.png wrote the plot over the input sequence's first picture
    import subprocess

    from stabilize.video import ffmpeg_exe

    frames = tmp_path / "f%03d.png"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", "samples/street/clip.mp4", "-frames:v", "6"]
    subprocess.run([*cmd, str(frames)], check=True)
    before = (tmp_path / "f001.png").read_bytes()
    args = ["evaluate", str(frames), str(frames), "--plot", str(tmp_path / "f001.png"), "-q"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2 and "is the input" in result.output
    assert (tmp_path / "f001.png").read_bytes() == before
