"""Where the focal length comes from: given, metadata, estimated, default."""

from __future__ import annotations

import math
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import flow
import stabilize.motion.focal as focal_module
from rotation.focal import FocalEstimate
from stabilize import Settings
from stabilize.motion.estimate import estimate_rotations
from stabilize.motion.focal import (
    FULL_FRAME_DIAGONAL_MM,
    FocalChoice,
    _kept_note,
    estimate_motion,
    initial_focal,
)
from stabilize.video import ffmpeg_exe, probe
from tests.stabilize.helpers import held_upright


def tagged(shaky: Path, folder: Path, mm: float) -> Path:
    """The clip with a phone's QuickTime 35 mm-equivalent focal-length key."""
    out = folder / "tagged.mov"
    key = f"com.apple.quicktime.camera.focal_length.35mm_equivalent={mm}"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shaky), "-c", "copy"]
    subprocess.run([*cmd, "-metadata", key, "-movflags", "use_metadata_tags", str(out)], check=True)
    return out


def test_the_metadata_focal_length_is_read(shaky, tmp_path):
    info = probe(tagged(shaky, tmp_path, 26.0))
    choice = initial_focal(Settings(), info, None)
    assert choice.source == "metadata"
    assert choice.px == pytest.approx(26.0 * (320**2 + 180**2) ** 0.5 / FULL_FRAME_DIAGONAL_MM)
    assert initial_focal(Settings(fov=50.0), info, None).source == "given"
    assert initial_focal(Settings(), probe(shaky), None).source == "default"


def test_a_focal_length_kept_is_said_with_the_option_that_gives_the_lens_own():
    # 1920 px across at 69° (the default) and at 52° (a phone's metadata)
    default = FocalChoice(960 / math.tan(math.radians(34.5)), 1920, "default")
    said = _kept_note(default)
    assert "the default's 69.0° (a phone's main camera) kept" in said
    assert said.endswith("--fov gives the lens's own")
    metadata = FocalChoice(960 / math.tan(math.radians(26.0)), 1920, "metadata")
    assert "the metadata's 52.0° kept" in _kept_note(metadata)


@pytest.fixture(scope="module")
def narrow_walk(tmp_path_factory) -> Path:
    """A rendered 40° clip, 2 s, of a shaken walk with a crowd."""
    from stabilize.synth import SynthOptions, render_clip

    folder = tmp_path_factory.mktemp("narrow")
    options = SynthOptions(size=(180, 320), seconds=2.0, seed=11, shake_deg=1.5, crowd=4)
    render_clip(folder, replace(options, hfov=40.0))
    return folder / "clip.mp4"


NARROW_TRUTH = 160.0 / math.tan(math.radians(20.0))


def test_auto_moves_a_wrong_start_towards_the_truth(narrow_walk):
    # A 40° clip started from the 69° default (47% off). The estimate is not yet within
    # the 3% that issue #15 asks (walking parallax biases it long, +14% here), but it
    # must land far closer than where it started.
    track, focal = estimate_motion(narrow_walk, probe(narrow_walk), Settings(fov="auto"))
    start = Settings().focal_px((180, 320))
    assert focal.source == "estimated" and track.samples is None
    assert abs(focal.px / NARROW_TRUTH - 1) < abs(start / NARROW_TRUTH - 1) / 3
    assert focal.summary()["fov_deg"] == pytest.approx(focal.fov_deg)


def test_a_long_clip_is_voted_once_at_the_focal_length_of_its_start(narrow_walk, monkeypatch):
    # The clip's 59 pairs are "long" once the estimate is made on 32: it is made on the
    # first 32 alone, and every pair is voted at what they give, as if it had been
    # given, bands and all
    searched = []
    search = focal_module.focal_from_track

    def seen(track, *args):
        searched.append(len(track.rotations))
        return search(track, *args)

    monkeypatch.setattr(focal_module, "MAX_PAIRS", 32)
    monkeypatch.setattr(focal_module, "focal_from_track", seen)
    info = probe(narrow_walk)
    track, focal = estimate_motion(narrow_walk, info, Settings(), bands=6)
    start = Settings().focal_px((180, 320))
    assert searched == [32] and focal.source == "estimated" and track.samples is None
    assert abs(focal.px / NARROW_TRUTH - 1) < abs(start / NARROW_TRUTH - 1) / 3
    given = estimate_rotations(narrow_walk, info, Settings(focal=focal.px), bands=6)
    for name in ("rotations", "residual", "bands", "band_support"):
        np.testing.assert_allclose(getattr(track, name), getattr(given, name), atol=1e-9)
    kept, _ = estimate_motion(narrow_walk, info, Settings(), bands=6, keep_samples=True)
    assert len(kept.samples.u) == 59


def phone_view(shared: Path, out: Path, crop: str, crf: int) -> Path:
    """phone-cc9's real frames cropped to ``crop`` (w:h:x:y) and shown at 640×480, as a
    phone's digital zoom does, encoded by x264 at ``crf``."""
    frames = shared / "data" / "phone-cc9" / "frames" / "RE_frame-%d.jpg"
    cmd = [ffmpeg_exe(), "-v", "error", "-framerate", "30", "-start_number", "99"]
    view = ["-vf", f"crop={crop},scale=640:480", "-c:v", "libx264", "-crf", str(crf)]
    subprocess.run([*cmd, "-i", str(frames), *view, "-pix_fmt", "yuv420p", str(out)], check=True)
    return out


@pytest.mark.parametrize("crop", ["320:240:246:189", "240:180:286:219"])  # 31°, 24°
def test_a_real_narrow_clip_is_estimated(shared, tmp_path, crop):
    # phone-cc9's real frames zoomed in, as a phone's digital zoom does: their middle
    # about the principal point (406.01, 309.01), shown at 640×480, so f is 573.85 px
    # times the zoom, where the 69° default (465.6 px) is 59% and 70% short. Their cost
    # curves rise 0.15–0.30% and 0.13–0.82% two coarse candidates past the minimum, 0.38%
    # and 0.41% at 15°. Measured: +3.7% and -0.7% (the 24° crop's fine grid has two
    # minima: read whole, it gave the lower one, -4.8%; walked down from the coarse
    # minimum, it gives the nearer; -1.2% and -2.7% before the texture gate; decoded to
    # grey instead of RGB, the 31° crop read +8.0%; the same 31° crop of
    # an H.264 copy of the frames, encoded twice, read +8%: its curve rose 0.09% two out,
    # which a rule asking for the rise there refused).
    clip = phone_view(shared, tmp_path / "zoomed.mp4", crop, crf=12)
    _, focal = estimate_motion(clip, probe(clip), Settings())
    assert focal.source == "estimated"
    assert focal.px == pytest.approx(573.85 * 640 / int(crop.split(":")[0]), rel=0.05)


def test_a_narrow_clip_that_pins_nothing_leaves_the_default_it_rules_out(shared, tmp_path):
    # phone-cc9's real frames zoomed in to 38° (f = 918.2 px at 640×480) and encoded at
    # CRF 28: the curve falls steeply to about the true f, then lies flat on the long
    # side (it rose 0.03% past its minimum, under MIN_RISE), so it pins nothing. It reads
    # the 69° default (465.6 px, -49%) 6.2% above its floor, and the nearest it accepts
    # is 852 px (-7%): on a narrow lens the default is the costly side (a rendered 30°
    # clip shook 5.16 px given 69°, 3.25 at 45°, 3.00 at 30°, 3.09 at 15°)
    clip = phone_view(shared, tmp_path / "zoomed.mp4", "400:300:206:159", crf=28)
    _, focal = estimate_motion(clip, probe(clip), Settings())
    truth, default = 573.85 * 640 / 400, Settings().focal_px((480, 640))
    assert focal.source == "estimated" and "rules out the default's 69.0°" in focal.note
    assert abs(focal.px / truth - 1) < abs(default / truth - 1) / 2


def test_the_search_spans_the_same_fields_of_view_however_the_camera_is_held(
    shaky, tmp_path, monkeypatch
):
    # 15–150° across the long side, as the default's 69°: a portrait clip's telephoto
    # (23° across its height, 13° across its width) lies inside it, as held level
    upright = held_upright(shaky, tmp_path)
    searched = []

    def search(*args):
        searched.append(args[-1])
        return FocalEstimate(None, np.zeros(0), np.zeros(0), 0)

    monkeypatch.setattr(focal_module, "estimate_focal", search)
    for clip in (shaky, upright):
        estimate_motion(clip, probe(clip), Settings())
    level, held_up = searched[0], searched[-1]
    assert probe(upright).size == (320, 180) and held_up == pytest.approx(level)
    width = flow.working_size((180, 320)).size[1]
    assert level[1] == pytest.approx(width / 2 / math.tan(math.radians(7.5)), rel=1e-3)


def montage(
    folder: Path, readout_ms: float = 0.0, fps: float = 30.0, seconds: float = 2.0
) -> tuple[Path, dict]:
    """A rendered 40° clip cut to a rendered 100° one, 2 s each (frames 0-59 | 60-119),
    and the second's true turns."""
    from stabilize.motion.files import read_rotations
    from stabilize.synth import SynthOptions, render_clip

    options = SynthOptions(size=(180, 320), seconds=seconds, fps=fps, shake_deg=1.5, crowd=4)
    for name, fov, seed in (("narrow", 40.0, 11), ("wide", 100.0, 12)):
        shot = replace(options, hfov=fov, seed=seed, rolling_shutter_ms=readout_ms)
        render_clip(folder / name, shot)
    joined = "[0:v][1:v]concat=n=2:v=1[v]"
    clips = ["-i", str(folder / "narrow" / "clip.mp4"), "-i", str(folder / "wide" / "clip.mp4")]
    cmd = [ffmpeg_exe(), "-v", "error", *clips, "-filter_complex", joined, "-map", "[v]"]
    subprocess.run([*cmd, "-c:v", "libx264", "-crf", "16", str(folder / "montage.mp4")], check=True)
    return folder / "montage.mp4", read_rotations(folder / "wide" / "truth.csv")


def test_a_montage_of_two_cameras_is_voted_shot_by_shot(tmp_path, monkeypatch):
    # one focal length for the clip, 43.0° (from its most turning pairs), read the 100°
    # shot's turns 0.53° off the truth on average; voted at its own, 97.3°, 0.09°
    from rotation import so3
    from rotation.camera import fov_from_focal

    clip, truth = montage(tmp_path)
    info = probe(clip)
    track, focal = estimate_motion(clip, info, Settings(), keep_samples=True)
    px = focal.per_frame(120)
    assert [first for first, _, _ in focal.shots][-1] == 60
    assert fov_from_focal(px[0], 320) == pytest.approx(40, rel=0.1)
    assert fov_from_focal(px[60], 320) == pytest.approx(100, rel=0.05)
    assert focal.said_shots(track.times).endswith("from 2.00 s")

    def off_deg(track) -> float:
        seen = so3.log_so3(track.rotations[60:119])
        true = np.array([truth[k] for k in sorted(truth)])
        return float(np.degrees(np.linalg.norm(seen - true, axis=1)).mean())

    assert off_deg(track) < 0.15
    monkeypatch.setattr(focal_module, "SHOT_APART", np.inf)  # as before: the clip's alone
    assert off_deg(estimate_motion(clip, info, Settings(), keep_samples=True)[0]) > 0.3


def test_a_240_fps_montage_is_searched_shot_by_shot_on_its_strides(tmp_path):
    # a 240 fps pair turns too little to pin a focal length down: on their pairs
    # neither shot did, and both were voted at the clip's one
    from rotation.camera import fov_from_focal

    clip, _ = montage(tmp_path, fps=240.0, seconds=1.5)
    _, focal = estimate_motion(clip, probe(clip), Settings())
    assert [first for first, _, _ in focal.shots][-1] == 360
    px = focal.per_frame(720)
    assert fov_from_focal(px[0], 320) == pytest.approx(40, rel=0.1)
    assert fov_from_focal(px[360], 320) == pytest.approx(100, rel=0.05)


def test_a_montage_of_two_cameras_is_warped_shot_by_shot(tmp_path):
    # under a rolling shutter: each shot's rows eased and its residual measured at its
    # own focal length, and each frame warped through its shot's K
    from stabilize import stabilize_video

    clip, _ = montage(tmp_path, readout_ms=30.0)
    summary, path = stabilize_video(clip, tmp_path / "out.mp4", Settings(rolling_shutter=30))
    wide = summary["focal"]["shots"][-1]
    assert wide["first_frame"] == 60 and wide["fov_deg"] == pytest.approx(100, rel=0.05)
    assert path.K.shape == (120, 3, 3) and path.K[60, 0, 0] == pytest.approx(wide["px"])
    assert path.K[59, 0, 0] > 2 * wide["px"]  # the 40° shot's
    assert summary["frames"] == 120 and path.row_corrections is not None
    assert any("shots of another camera, each at its own" in n for n in summary["notices"])
