"""Rendered rolling-shutter clips: the readout found from the video alone, the jello
undone, and a global-shutter clip left as it was."""

from pathlib import Path

import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.evaluate.metrics import evaluate, evaluate_pair
from stabilize.synth import SynthOptions, render_clip
from stabilize.video import probe, read_frames
from tests.stabilize.helpers import held_upright

SIZE = (270, 480)


def rendered(folder: Path, readout_ms: float) -> Path:
    opts = SynthOptions(
        size=SIZE, seconds=2.5, seed=21, shake_deg=3.0, crowd=4, rolling_shutter_ms=readout_ms
    )
    render_clip(folder, opts)
    return folder / "clip.mp4"


def measured(original: Path, output: Path):
    info = probe(original)
    _, after = evaluate_pair(read_frames(original, info=info), read_frames(output, info.size))
    return after


def alone(output: Path):
    """The output's own metrics (its wobble, shake): what :func:`measured` reads of them,
    without registering the original too (half the time)."""
    return evaluate(read_frames(output))


@pytest.fixture(scope="module")
def jello(tmp_path_factory) -> Path:
    return rendered(tmp_path_factory.mktemp("jello"), 25.0)


WHOLE = Settings(fov=70.0, max_zoom=1.3, max_stretch=100.0)  # the whole correction
OFF = Settings(fov=70.0, max_zoom=1.3, rolling_shutter="off")


@pytest.fixture(scope="module")
def runs(jello, tmp_path_factory) -> dict:
    """(summary, path, output's metrics) of the jello clip stabilised with the whole
    correction and without any, made once for the tests that compare with them (the
    distortion, against the original, is read of the whole correction's alone)."""
    folder = tmp_path_factory.mktemp("runs")
    out = {}
    for name, settings in (("whole", WHOLE), ("off", OFF)):
        output = folder / f"{name}.mp4"
        summary, planned = stabilize_video(jello, output, settings)
        read = measured(jello, output) if name == "whole" else alone(output)
        out[name] = (summary, planned, read)
    return out


def test_the_readout_is_found_and_the_wobble_undone(runs):
    summary, planned, corrected = runs["whole"]
    found = summary["rolling_shutter"]
    assert found["source"] == "estimated" and found["readout_ms"] == pytest.approx(25.0, abs=2.5)
    assert planned.row_corrections is not None
    summary_off, planned_off, uncorrected = runs["off"]
    assert summary_off["rolling_shutter"]["source"] == "off"
    assert planned_off.row_corrections is None
    assert corrected.wobble_px < 0.4 * uncorrected.wobble_px


def test_a_phone_held_upright_has_its_readout_found_and_its_wobble_undone(jello, runs, tmp_path):
    # stored level with a display rotation: its rows are the sensor's, as held level.
    # The same stream: uncorrected, it wobbles as the level clip does (runs["off"])
    upright = held_upright(jello, tmp_path)
    summary, _ = stabilize_video(upright, tmp_path / "auto.mp4", WHOLE)
    assert summary["rolling_shutter"]["readout_ms"] == pytest.approx(25.0, abs=2.5)
    corrected = alone(tmp_path / "auto.mp4").wobble_px
    assert corrected < 0.4 * runs["off"][2].wobble_px


def test_the_correction_stretches_no_frame_past_the_budget(jello, runs, tmp_path):
    # 3° of shake a frame under a 25 ms readout: undoing the rows' turns whole would
    # shear frames by several %, which the metric reads as distortion
    whole_summary, _, full = runs["whole"]
    assert whole_summary["stretch_eased_frames"] == 0
    told: list[str] = []
    summary, _ = stabilize_video(
        jello, tmp_path / "eased.mp4", Settings(fov=70.0, max_zoom=1.3), notify=told.append
    )
    assert summary["stretch_eased_frames"] > 0
    assert any("eased" in line and "--max-stretch" in line for line in told)
    eased = measured(jello, tmp_path / "eased.mp4")
    assert full.distortion < 0.97
    assert eased.distortion > 0.985


def test_a_global_shutter_clip_is_left_alone(tmp_path):
    clip = rendered(tmp_path / "global", 0.0)
    summary, planned = stabilize_video(clip, tmp_path / "auto.mp4", Settings(fov=70.0))
    assert summary["rolling_shutter"]["readout_ms"] == 0.0
    assert planned.row_corrections is None
    _, plain = stabilize_video(
        clip, tmp_path / "off.mp4", Settings(fov=70.0, rolling_shutter="off")
    )
    np.testing.assert_allclose(planned.homographies, plain.homographies)
