"""Where the focal length comes from: given, metadata, estimated, default."""

from __future__ import annotations

import math
import subprocess
from dataclasses import replace
from pathlib import Path

import pytest

from stabilize import Settings
from stabilize.motion.focal import FULL_FRAME_DIAGONAL_MM, estimate_motion, initial_focal
from stabilize.video import ffmpeg_exe, probe


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


def test_auto_moves_a_wrong_start_towards_the_truth(tmp_path):
    # A 40° clip started from the 69° default (47% off). The estimate is not yet within
    # the 3% that issue #15 asks (walking parallax biases it long, +14% here), but it
    # must land far closer than where it started.
    from stabilize.synth import SynthOptions, render_clip

    options = SynthOptions(size=(180, 320), seconds=2.0, seed=11, shake_deg=1.5, crowd=4)
    render_clip(tmp_path, replace(options, hfov=40.0))
    truth = 160.0 / math.tan(math.radians(20.0))
    clip = tmp_path / "clip.mp4"
    track, focal = estimate_motion(clip, probe(clip), Settings(fov="auto"))
    start = Settings().focal_px(320)
    assert focal.source == "estimated" and track.samples is None
    assert abs(focal.px / truth - 1) < abs(start / truth - 1) / 3
    assert focal.summary()["fov_deg"] == pytest.approx(focal.fov_deg)


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
    frames = shared / "data" / "phone-cc9" / "frames" / "RE_frame-%d.jpg"
    clip = tmp_path / "zoomed.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-framerate", "30", "-start_number", "99"]
    view = ["-vf", f"crop={crop},scale=640:480", "-c:v", "libx264", "-crf", "12"]
    subprocess.run([*cmd, "-i", str(frames), *view, "-pix_fmt", "yuv420p", str(clip)], check=True)
    _, focal = estimate_motion(clip, probe(clip), Settings())
    assert focal.source == "estimated"
    assert focal.px == pytest.approx(573.85 * 640 / int(crop.split(":")[0]), rel=0.05)
