"""The source's colour description (range, matrix, primaries, transfer) is read and kept:
a full-range clip comes out full range, its tones unchanged, its borders black."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from stabilize import Settings, stabilize_video
from stabilize.video import Encoding, ffmpeg_exe, probe, read_frames
from stabilize.video.colour import Colour, colour_of
from stabilize.video.i420 import black

BT709 = ("bt709",) * 3


@pytest.mark.parametrize(
    ("pix_fmt", "details", "expected"),
    [
        ("yuvj420p", "tv, bt709, progressive", Colour("pc", *BT709)),  # GoPro's: yuvj wins
        ("yuv420p", "pc, bt709", Colour("pc", *BT709)),
        (
            "yuv420p10le",
            "tv, bt2020nc/bt2020/smpte2084",
            Colour("tv", "bt2020nc", "bt2020", "smpte2084"),
        ),
        ("yuvj444p", "pc, bt709/unknown/unknown", Colour("pc", "bt709")),
        ("yuv420p", "tv, progressive", Colour("tv")),
        ("yuv444p", "", Colour()),
    ],
)
def test_the_description_ffmpeg_lists_is_read(pix_fmt, details, expected):
    assert colour_of(pix_fmt, details) == expected


def test_what_is_unknown_is_not_stated():
    assert Colour("tv").ffmpeg_args() == ["-color_range", "tv"]
    assert Colour().ffmpeg_args() == []


def test_black_is_zero_luma_in_full_range():
    frame = np.zeros((12, 8), np.uint8)
    assert black(frame) == (16, 128, 128)
    assert black(frame, full_range=True) == (0, 128, 128)
    assert black(frame.astype(np.uint16), full_range=True) == (0, 512, 512)


# A full-range BT.709 clip, as a phone or a GoPro writes one (as output options alone,
# FFmpeg drops the primaries and transfer it converts to)
FULL_RANGE = (
    "scale=out_range=pc:out_color_matrix=bt709,format=yuvj420p,"
    "setparams=range=pc:colorspace=bt709:color_primaries=bt709:color_trc=bt709"
)


def _full_range(source: list[str], out: Path) -> Path:
    cmd = [ffmpeg_exe(), "-v", "error", "-y", *source, "-vf", FULL_RANGE]
    subprocess.run([*cmd, "-c:v", "libx264", "-crf", "12", str(out)], check=True)
    return out


def _luma(path: Path) -> NDArray:
    """The clip's luma samples (N, H, W), as stored."""
    frames = read_frames(path, pix_fmt="yuv420p")
    return np.array([frame[: frame.shape[0] * 2 // 3] for frame in frames])


def test_a_full_range_clip_keeps_its_range_and_its_samples(tmp_path):
    bars = ["-f", "lavfi", "-i", "smptehdbars=s=320x180:r=15:d=2"]  # still: an identity warp
    source = _full_range(bars, tmp_path / "bars.mp4")
    assert probe(source).colour == Colour("pc", *BT709)
    out = tmp_path / "out.mp4"
    stabilize_video(source, out, Settings())
    assert probe(out).colour == Colour("pc", *BT709)  # tagged limited before: stretched
    # stated only on the output side, FFmpeg squeezed the samples into limited range
    difference = np.abs(_luma(out).astype(int) - _luma(source))
    assert np.median(difference) <= 1 and np.percentile(difference, 99) <= 4


def test_borders_are_black_in_full_range(shaky, tmp_path):
    source = _full_range(["-i", str(shaky)], tmp_path / "full.mp4")
    out = tmp_path / "out.mp4"
    stabilize_video(source, out, Settings(crop="none"))  # the borders show
    corners = _luma(out)[:, [0, 0, -1, -1], [0, -1, 0, -1]]
    assert corners.min() <= 2  # limited range's black, 16, is a dark grey here


def test_a_source_that_says_nothing_gets_the_encoders_defaults(shaky, tmp_path):
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(shaky, out, Settings())
    assert probe(out).colour.range in (None, "tv")
    # 8 bits: H.264, which every player plays
    assert summary["encoder"] == {"codec": "libx264", "pix_fmt": "yuv420p"}
    assert probe(out).codec == "h264"


MASTERING = "G(13250,34500)B(7500,3000)R(34000,16000)WP(15635,16450)L(10000000,50)"


@pytest.fixture(scope="module")
def hdr10(shaky, tmp_path_factory) -> Path:
    """The shaky clip as HDR10 HEVC: PQ, BT.2020, with its mastering display (P3 on a
    1000 cd/m² monitor) and light levels in its frames' SEI, as a phone writes it."""
    out = tmp_path_factory.mktemp("hdr10") / "hdr10.mp4"
    x265 = f"hdr10=1:master-display={MASTERING}:max-cll=1000,400:log-level=error"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-c:v", "libx265"]
    cmd += ["-preset", "ultrafast", "-pix_fmt", "yuv420p10le", "-x265-params", x265]
    subprocess.run([*cmd, "-c:a", "copy", str(out)], check=True)
    return out


@pytest.mark.parametrize("codec", ["libx264", "libx265"])
def test_hdr10_metadata_is_read_and_written_again(hdr10, tmp_path, codec):
    source = probe(hdr10).colour
    assert source.mastering == MASTERING and source.light == "1000,400"
    out = tmp_path / "out.mkv"
    settings = Settings(fov=70.0, encoding=Encoding(codec=codec, preset="ultrafast"))
    summary, _ = stabilize_video(hdr10, out, settings)
    written = probe(out).colour
    assert (written.mastering, written.light) == (MASTERING, "1000,400")
    assert not any("HDR10" in n for n in summary["notices"])


def test_a_deep_source_written_at_8_bits_is_said(hdr10, tmp_path):
    # MPEG-2 (a DVD's) holds 8 bits: the two lost went silently
    summary, _ = stabilize_video(hdr10, tmp_path / "out.mpg", Settings(fov=70.0))
    assert probe(tmp_path / "out.mpg").pix_fmt == "yuv420p"
    assert (
        "yuv420p10le video written at 8 bits: mpeg2video (yuv420p) holds no more"
        in (summary["notices"])
    )


def test_hdr10_metadata_an_encoder_cannot_write_is_said_lost(hdr10, tmp_path):
    summary, _ = stabilize_video(hdr10, tmp_path / "out.webm", Settings(fov=70.0))
    assert any("HDR10's mastering display" in n for n in summary["notices"])


# One scene of HDR10+ metadata, in the JSON x265 reads (Samsung's format)
HDR10_PLUS = {
    "JSONInfo": {"HDR10plusProfile": "A", "Version": "1.0"},
    "SceneInfo": [{
        "BezierCurveData": {"Anchors": [256, 512, 768, 1024, 1280, 1536, 1792, 2048, 2304],
                            "KneePointX": 100, "KneePointY": 100},
        "LuminanceParameters": {
            "AverageRGB": 100, "MaxScl": [500, 500, 500],
            "LuminanceDistributions": {"DistributionIndex": [1, 5, 10, 25, 50, 75, 90, 95, 99],
                                       "DistributionValues": [1, 2, 3, 4, 5, 6, 7, 8, 9]},
        },
        "NumberOfWindows": 1, "TargetedSystemDisplayMaximumLuminance": 1000,
        "SceneFrameIndex": 0, "SceneId": 0, "SequenceFrameIndex": 0,
    }],
    "SceneInfoSummary": {"SceneFirstFrameIndex": [0], "SceneFrameNumbers": [1]},
    "ToolInfo": {"Tool": "test", "Version": "1"},
}  # fmt: skip


def test_hdr10_plus_left_out_is_said(shaky, tmp_path):
    # a Samsung phone's HDR video: its tone mapping for each frame went silently
    import json

    (tmp_path / "plus.json").write_text(json.dumps(HDR10_PLUS))
    clip = tmp_path / "plus.mp4"
    x265 = (
        f"hdr10=1:master-display={MASTERING}:log-level=error:dhdr10-info={tmp_path / 'plus.json'}"
    )
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-t", "0.3", "-c:v", "libx265"]
    cmd += ["-preset", "ultrafast", "-pix_fmt", "yuv420p10le", "-x265-params", x265]
    subprocess.run([*cmd, "-an", str(clip)], check=True)
    assert probe(clip).colour.hdr10_plus and not probe(shaky).colour.hdr10_plus
    summary, _ = stabilize_video(clip, tmp_path / "out.mp4", Settings(fov=70.0))
    assert any(n.startswith("HDR10+ (its tone mapping") for n in summary["notices"])


IPHONE_HDR = """Input #0, mov,mp4,m4a,3gp,3g2,mj2, from 'IMG_0001.MOV':
  Duration: 00:00:02.00, start: 0.000000, bitrate: 20000 kb/s
  Stream #0:0[0x1](und): Video: hevc (Main 10) (hvc1 / 0x31637668), yuv420p10le(tv, \
bt2020nc/bt2020/arib-std-b67), 1920x1080, 19000 kb/s, 30 fps, 30 tbr, 600 tbn (default)
      Metadata:
        handler_name    : Core Media Video
      Side data:
        DOVI configuration record: version: 1.0, profile: 8, level: 4, rpu flag: 1, \
el flag: 0, bl flag: 1, compatibility id: 4
  Stream #0:1[0x2](und): Audio: aac (LC) (mp4a / 0x6134706D), 44100 Hz, stereo, fltp
"""


def test_dolby_vision_is_read_from_the_video_streams_own_listing(tmp_path, monkeypatch):
    clip = tmp_path / "IMG_0001.MOV"
    clip.write_bytes(b"")

    def listed(text):  # FFmpeg's listing of the file, and of its first frame
        result = subprocess.CompletedProcess([], 1, "", text)
        monkeypatch.setattr(subprocess, "run", lambda *a, **k: result)
        return probe(clip).colour

    assert listed(IPHONE_HDR).dolby_vision == "8.4"
    assert listed(IPHONE_HDR).transfer == "arib-std-b67"
    # a record of another stream's (here a second video stream's) is not the first's
    video, record = IPHONE_HDR.split("      Side data:\n")
    record, audio = record.split("  Stream #0:1")
    second = video.replace("#0:0[0x1]", "#0:1[0x2]") + "      Side data:\n" + record
    plain = video + second + "  Stream #0:2" + audio
    assert listed(plain).dolby_vision is None


def test_closed_captions_in_the_video_are_read_from_its_line(tmp_path, monkeypatch):
    # a US broadcast recording: EIA-608 captions in the H.264 frames' SEI
    clip = tmp_path / "news.ts"
    clip.write_bytes(b"")
    listing = IPHONE_HDR.split("      Metadata")[0].replace(
        "1920x1080, 19000 kb/s", "1920x1080 [SAR 1:1 DAR 16:9], Closed Captions"
    )
    result = subprocess.CompletedProcess([], 1, "", listing)
    monkeypatch.setattr(subprocess, "run", lambda *a, **k: result)
    assert probe(clip).captions
    result.stderr = IPHONE_HDR
    assert not probe(clip).captions
