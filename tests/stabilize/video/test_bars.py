"""Black bars baked into the frame: found, the picture inside them decoded alone, and
the bars put back around it."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from stabilize.video import ffmpeg_exe, i420, probe, read_frames
from stabilize.video.bars import detect_bars, put_back
from tests.stabilize.helpers import SAMPLE, boxed


@pytest.mark.parametrize(
    ("pad", "bars"),
    [
        ("640:480:0:60", (60, 60, 0, 0)),  # a letterbox: 16:9 shown in 4:3
        # a pillarbox: 4:2:0 puts the picture at an even column, 106 (the right bar 108)
        ("854:360:107:0", (0, 0, 106, 108)),
        # a clip shot upright, shown in a wide frame: the picture a third of its width
        ("640:360:219:0", (0, 0, 218, 220)),
    ],
)
def test_bars_are_found_and_the_picture_inside_them_decoded_alone(tmp_path, pad, bars):
    upright = pad.startswith("640:360")  # the sample's middle 202×360 first
    clip = boxed(SAMPLE / "clip.mp4", tmp_path, pad, "crop=202:360" if upright else "")
    info = probe(clip)
    assert detect_bars(info) == bars
    inside = info.within_bars(bars)
    top, bottom, left, right = bars
    assert inside.framed_size == info.size
    assert inside.size == (info.height - top - bottom, info.width - left - right)
    picture = np.stack(list(read_frames(clip, info=inside)))
    whole = np.stack(list(read_frames(clip, info=info)))
    h, w = inside.size
    np.testing.assert_array_equal(picture, whole[:, top : top + h, left : left + w])


def test_a_clip_without_bars_has_none():
    assert detect_bars(probe(SAMPLE / "clip.mp4")) is None
    info = probe(SAMPLE / "clip.mp4")
    assert info.within_bars(None) is info


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_the_bars_are_put_back_in_the_ranges_black(dtype):
    y = np.full((4, 6), 200, dtype)
    u, v = np.full((2, 3), 100, dtype), np.full((2, 3), 90, dtype)
    framed = put_back(i420.join(y, u, v), (2, 2, 4, 0), planar=True, full_range=True)
    fy, fu, fv = i420.split(framed)
    assert fy.shape == (8, 10) and fu.shape == fv.shape == (4, 5)
    np.testing.assert_array_equal(fy[2:6, 4:], y)
    np.testing.assert_array_equal(fu[1:3, 2:], u)
    black = i420.black(framed, full_range=True)
    assert fy[0, 0] == black[0] and fu[0, 0] == black[1] and fv[-1, 0] == black[2]


@pytest.mark.parametrize(
    ("bands", "found"),
    [
        # full range: black is 0, as FFmpeg's pad puts it
        ("format=yuvj420p,scale=640:280,pad=640:360:0:40:black", True),
        # and a night's dark edges, at 20 of 255, are picture (cropdetect's own limit,
        # 24, took them for bars)
        (
            "format=yuvj420p,drawbox=y=0:w=iw:h=40:color=0x050505:t=fill,"
            "drawbox=y=ih-40:w=iw:h=40:color=0x050505:t=fill",
            False,
        ),
    ],
)
def test_bars_of_a_full_range_picture_are_its_black_alone(tmp_path, bands, found):
    clip = tmp_path / "dark.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(SAMPLE / "clip.mp4"), "-vf", bands]
    subprocess.run([*cmd, "-pix_fmt", "yuvj420p", "-crf", "12", str(clip)], check=True)
    info = probe(clip)
    assert info.colour.full_range
    assert detect_bars(info) == ((40, 40, 0, 0) if found else None)
