"""Interlaced video: its field order read, and its frames deinterlaced on decoding, one
for each frame."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from stabilize.video import ffmpeg_exe, frame_times, probe, read_frames
from stabilize.video.fields import field_order
from tests.stabilize.conftest import render
from tests.stabilize.helpers import combing, woven


@pytest.fixture(scope="module")
def scene50(tmp_path_factory) -> Path:
    """A rendered street shaken 1.5° at 50 fps: the two fields of a 25i frame."""
    return render(tmp_path_factory.mktemp("scene50"), seed=5, shake_deg=1.5, fps=50.0, seconds=1.0)


@pytest.mark.parametrize(
    ("details", "order"),
    [
        ("tv, bt709, progressive", "progressive"),
        ("pc, bt709, top first", "tff"),
        ("bottom first", "bff"),
        ("tv, top coded first (swapped)", "tff"),
        ("tv, bottom coded first (swapped)", "bff"),
        ("tv, bt709", ""),
        ("", ""),
    ],
)
def test_the_field_order_is_read_from_ffmpegs_words(details, order):
    assert field_order(details) == order


def test_an_interlaced_stream_is_deinterlaced_frame_for_frame(scene50, tmp_path):
    clip = woven(scene50, tmp_path)
    info = probe(clip)
    assert info.field_order == "tff" and info.deinterlace
    frames = [combing(f) for f in read_frames(clip, info=info)]
    woven_frames = [combing(f) for f in read_frames(clip, info=info.deinterlaced("off"))]
    assert len(frames) == len(woven_frames) == len(frame_times(clip)) == 25
    # woven fields of a shaking scene comb every frame (1.26), and deinterlaced they
    # comb less than the 50 fps source's own frames do (0.32 against 0.50)
    progressive = np.median([combing(f) for f in read_frames(scene50)])
    assert np.median(woven_frames) > 2 * progressive
    assert np.median(frames) < 1.2 * progressive


def test_a_progressive_stream_is_decoded_as_it_is(scene50):
    info = probe(scene50)
    assert info.field_order == "progressive" and not info.deinterlace
    assert info.deinterlaced("auto") == info and info.deinterlaced("on").deinterlace


def test_an_unknown_deinterlace_mode_is_refused(scene50):
    with pytest.raises(ValueError, match="--deinterlace must be one of auto, on, off"):
        probe(scene50).deinterlaced("sideways")


def test_a_stream_whose_header_names_no_field_order_is_read_from_its_frames(scene50, tmp_path):
    # DV, a camcorder's tape format, in AVI: its frames are flagged interlaced, its
    # stream header says nothing of fields
    dv, mjpeg = tmp_path / "tape.avi", tmp_path / "mjpeg.avi"
    weave = "scale=720:576,tinterlace=mode=interleave_top,setfield=tff"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(scene50), "-an"]
    subprocess.run(
        [*cmd, "-vf", weave, "-c:v", "dvvideo", "-pix_fmt", "yuv420p", str(dv)], check=True
    )
    subprocess.run([*cmd, "-c:v", "mjpeg", str(mjpeg)], check=True)
    header = subprocess.run(
        [ffmpeg_exe(), "-hide_banner", "-i", str(dv)], capture_output=True, text=True
    )
    assert "first" not in header.stderr and "progressive" not in header.stderr
    assert probe(dv).field_order == "tff" and probe(dv).deinterlace
    assert probe(mjpeg).field_order == "progressive" and not probe(mjpeg).deinterlace
