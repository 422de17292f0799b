"""Pass 2's pipe to the encoder: I420 where that loses nothing the output keeps, RGB at
the source's depth where a side is odd or where colour finer than 4:2:0 is bound for an
encoder that keeps it."""

from __future__ import annotations

import subprocess
from dataclasses import replace
from pathlib import Path

import av
import cv2
import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.video import Encoding, ffmpeg_exe, probe, read_frames
from stabilize.video.containers import container_for
from stabilize.warp.render import piped_format
from tests.stabilize.helpers import SAMPLE

STILL = Settings(fov=70.0, crop="none")  # a still clip, uncropped: every warp the identity


@pytest.mark.parametrize(
    ("source", "out", "codec", "piped"),
    [
        ("yuv420p", "out.mp4", None, "yuv420p"),
        ("yuv422p10le", "out.mp4", None, "yuv420p10le"),  # written 4:2:0 for players
        ("yuv422p10le", "out.mov", "prores_ks", "rgb48le"),
        ("yuv422p", "out.mxf", "dnxhd", "rgb24"),
        ("yuv420p", "out.mov", "prores_ks", "yuv420p"),  # nothing finer to keep
        ("rgb24", "f/%05d.png", None, "rgb24"),
        ("gbrp16le", "f/%05d.tif", None, "rgb48le"),
        ("yuv420p", "f/%05d.png", None, "yuv420p"),
        ("yuvj444p", "f/%05d.jpg", None, "yuv420p"),  # JPEG pictures are written 4:2:0
        ("yuv444p", "out.gif", None, "rgb24"),  # a palette of the frames' own colours
        ("gray", "out.mov", "prores_ks", "yuv420p"),
    ],
)
def test_the_pipe_keeps_what_the_encoder_keeps(source, out, codec, piped):
    info = replace(probe(SAMPLE / "clip.mp4"), pix_fmt=source)
    settings = Settings(encoding=Encoding(codec=codec))
    assert piped_format(info, settings, container_for(out)) == piped


@pytest.mark.parametrize(
    ("source", "asked", "piped"),
    [
        ("yuv422p10le", "yuv422p10le", "rgb48le"),
        ("yuv422p", "yuv420p", "yuv420p"),
        ("yuv420p", "yuv444p", "yuv420p"),  # no finer colour to keep
        ("rgb24", "yuv444p", "rgb24"),
    ],
)
def test_the_pipe_keeps_what_a_pixel_format_asked_for_keeps(source, asked, piped):
    info = replace(probe(SAMPLE / "clip.mp4"), pix_fmt=source)
    settings = Settings(encoding=Encoding(pix_fmt=asked))
    assert piped_format(info, settings, container_for("out.mkv")) == piped


def test_an_odd_side_pipes_rgb_at_the_sources_depth():
    info = replace(probe(SAMPLE / "clip.mp4"), pix_fmt="yuv420p10le", width=319)
    assert piped_format(info, Settings(), container_for("out.mkv")) == "rgb48le"


def _striped(axis: int = 0) -> np.ndarray:
    """The sample's first frame (RGB), its rows (``axis`` 0; 1: columns) alternately
    warmer and cooler: the finest colour detail, which 4:2:0 averages away (and 4:2:2,
    across)."""
    rgb = np.moveaxis(next(iter(read_frames(SAMPLE / "clip.mp4"))).astype(np.int16), axis, 0)
    rgb[0::2, ..., 0] += 40
    rgb[1::2, ..., 2] += 40
    return np.moveaxis(np.clip(rgb, 0, 255).astype(np.uint8), 0, axis)


def _write_png(path: Path, rgb: np.ndarray) -> None:
    cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))


def _still_clip(folder: Path, pix_fmt: str, codec: str, suffix: str, axis: int = 0) -> Path:
    """Six frames of the striped picture (:func:`_striped`), encoded so."""
    picture, clip = folder / "still.png", folder / f"still{suffix}"
    _write_png(picture, _striped(axis))
    cmd = [ffmpeg_exe(), "-v", "error", "-loop", "1", "-framerate", "30", "-i", str(picture)]
    cmd += ["-frames:v", "6", "-c:v", codec, "-pix_fmt", pix_fmt, str(clip)]
    subprocess.run(cmd, check=True)
    return clip


def _planes(path: Path, pix_fmt: str) -> np.ndarray:
    """The first frame's raw planes, as FFmpeg decodes them to ``pix_fmt``."""
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(path), "-frames:v", "1"]
    raw = subprocess.run([*cmd, "-f", "rawvideo", "-pix_fmt", pix_fmt, "-"], capture_output=True)
    return np.frombuffer(raw.stdout, np.uint16 if pix_fmt.endswith("le") else np.uint8)


@pytest.mark.parametrize(
    "encoding",
    [Encoding(codec="prores_ks"), Encoding(codec="libx264", crf=0, pix_fmt="yuv422p10le")],
    ids=["prores", "pix-fmt"],
)
def test_a_4_2_2_source_keeps_its_colour(tmp_path, encoding):
    # ProRes 422 in, ProRes 422 out: the frames travelled as 4:2:0, which halved the
    # colour's rows (a notice said so); H.264 4:2:2 could not be asked for
    clip = _still_clip(tmp_path, "yuv422p10le", "prores_ks", ".mov")
    out = tmp_path / "out.mov"
    summary, _ = stabilize_video(clip, out, replace(STILL, encoding=encoding))
    assert not any("colour" in n for n in summary["notices"])
    assert probe(out).pix_fmt == "yuv422p10le"
    h, w = probe(clip).size
    source, written = (_planes(p, "yuv422p10le").astype(float) for p in (clip, out))
    red = [p[h * w + h * w // 2 :].reshape(h, w // 2) for p in (source, written)]  # Cr
    stripes = [np.abs(np.diff(v[8:-8, 8:-8], axis=0)).mean() for v in red]
    assert stripes[1] > 0.9 * stripes[0] > 20  # row to row, as the source has it
    assert np.abs(red[1] - red[0])[8:-8, 8:-8].mean() < 2  # of 1023


@pytest.mark.parametrize(
    ("codec", "suffix", "profile"), [("prores_ks", ".mov", "4444"), ("dnxhd", ".mxf", "DNXHR 444")]
)
def test_a_4_4_4_source_into_an_editing_codec_keeps_its_colour(tmp_path, codec, suffix, profile):
    # a ProRes 4444 master came back as ProRes 422 HQ, its colour halved across, with a
    # notice naming --pix-fmt as the way to keep it
    clip = _still_clip(tmp_path, "yuv444p10le", "prores_ks", ".mov", axis=1)
    out = tmp_path / f"out{suffix}"
    summary, _ = stabilize_video(clip, out, replace(STILL, encoding=Encoding(codec=codec)))
    assert not any("colour" in n for n in summary["notices"])
    assert probe(out).pix_fmt in ("yuv444p10le", "yuv444p12le")  # ProRes 4444 decodes at 12
    with av.open(str(out)) as written:
        assert written.streams.video[0].codec_context.profile == profile
    h, w = probe(clip).size
    source, written = (_planes(p, "yuv444p10le").astype(float) for p in (clip, out))
    red = [p[2 * h * w :].reshape(h, w) for p in (source, written)]  # Cr, full width
    stripes = [np.abs(np.diff(v[8:-8, 8:-8], axis=1)).mean() for v in red]
    assert stripes[1] > 0.9 * stripes[0] > 20  # column to column, as the source has it
    assert np.abs(red[1] - red[0])[8:-8, 8:-8].mean() < 2  # of 1023


def test_rgb_pictures_stay_exact_through_a_still_clip(tmp_path):
    # PNG pictures in and out travelled as 4:2:0, each pixel's colour shared with three
    folder, picture = tmp_path / "in", _striped()
    folder.mkdir()
    for k in range(1, 7):
        _write_png(folder / f"{k:03d}.png", picture)
    out = tmp_path / "out" / "%03d.png"
    stabilize_video(folder / "%03d.png", out, replace(STILL, fps=30.0))
    written = list(read_frames(out))
    assert len(written) == 6
    np.testing.assert_array_equal(written[0], picture)


def test_a_deep_source_with_an_odd_side_keeps_its_depth(shaky, tmp_path):
    # an odd side sent the frames through 8-bit RGB, whatever the encoder held
    clip = tmp_path / "odd.mkv"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "8", "-vf"]
    subprocess.run([*cmd, "format=rgb48le,crop=319:179", "-c:v", "ffv1", str(clip)], check=True)
    summary, _ = stabilize_video(clip, tmp_path / "out.mkv", Settings(fov=70.0))
    assert not any("8 bits" in n for n in summary["notices"])
    assert probe(tmp_path / "out.mkv").pix_fmt == "yuv420p10le"
