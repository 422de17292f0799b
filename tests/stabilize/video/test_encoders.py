"""Each encoder's quality and speed: --crf and --preset on its own scale."""

import av
import numpy as np
import pytest

from stabilize.video import Encoding, FrameWriter
from stabilize.video.encoders import encoder_args, unused_options
from stabilize.video.preflight import check_encoder


def test_each_encoder_takes_the_quality_on_its_own_scale():
    assert encoder_args("libx264", None, "medium") == [
        "-c:v", "libx264", "-crf", "18", "-preset", "medium",
    ]  # fmt: skip
    assert encoder_args("libvpx-vp9", None, "veryslow")[2:4] == ["-crf", "31"]
    assert "-cpu-used" in encoder_args("libvpx-vp9", 20, "ultrafast")
    assert encoder_args("mjpeg", 18, "medium")[2:] == ["-q:v", "2"]  # the usual best
    assert encoder_args("mpeg2video", 1000, "medium")[2:] == ["-q:v", "31"]  # at most 31
    assert encoder_args("png", 10, "medium") == ["-c:v", "png"]


@pytest.mark.parametrize(
    ("codec", "crf", "heard"),
    [
        ("png", 10, "--crf 10 has no effect on png: it keeps every sample"),
        ("tiff", 0, "--crf 0 has no effect on tiff: it keeps every sample"),
        ("gif", 30, "--crf 30 has no effect on gif: its palette is its quality"),
        ("prores_ks", 20, "--crf 20 has no effect on prores_ks: its profile is its quality"),
        ("png", None, None),  # not given: nothing to say
        ("libx264", 23, None),
        ("mjpeg", 23, None),
        ("some-new-encoder", 23, None),  # gets -crf as it is
    ],
)
def test_a_crf_with_no_effect_is_said(codec, crf, heard):
    assert unused_options(codec, crf) == ((heard,) if heard else ())


@pytest.mark.parametrize(
    ("codec", "preset", "heard"),
    [
        ("prores_ks", "veryslow", "--preset veryslow has no effect on prores_ks"),
        ("png", "fast", "--preset fast has no effect on png"),
        ("mjpeg", "slow", "--preset slow has no effect on mjpeg"),
        ("libtheora", "slow", "--preset slow has no effect on libtheora"),
        ("prores_ks", "medium", None),  # the default: not given
        ("libx264", "veryslow", None),
        ("libvpx-vp9", "veryslow", None),  # its -cpu-used
        ("some-new-encoder", "slow", None),  # gets -preset as it is
    ],
)
def test_a_preset_with_no_effect_is_said(codec, preset, heard):
    said = unused_options(codec, None, preset)
    assert said == () if heard is None else said[0].startswith(heard)


@pytest.mark.parametrize("codec", ["dnxhd", "prores_ks", "prores_aw"])
@pytest.mark.parametrize("pix_fmt", ["yuv420p", "yuv420p10le"])
def test_editing_codecs_take_any_size_at_either_depth(tmp_path, codec, pix_fmt):
    # --codec dnxhd was refused at 320x180 ("video parameters incompatible with DNxHD"),
    # and took -crf and -preset it has no use for
    encoding = Encoding(codec=codec, pix_fmt=pix_fmt)
    check_encoder(tmp_path / "out.mov", encoding, (180, 320))
    check_encoder(tmp_path / "out.mxf", encoding, (180, 320), 25.0)


@pytest.mark.parametrize(
    ("codec", "suffix", "profile"),
    [("prores_ks", ".mov", "4444"), ("prores_aw", ".mov", "4444"), ("dnxhd", ".mxf", "DNXHR 444")],
)
def test_editing_codecs_write_4_4_4_in_their_4_4_4_profile(tmp_path, codec, suffix, profile):
    # ProRes wrote 4:4:4 pixels as a 422 HQ file (apch), DNxHR refused them
    out = tmp_path / f"out{suffix}"
    asked = Encoding(codec=codec, pix_fmt="yuv444p10le")
    with FrameWriter(out, (180, 320), 25.0, asked) as writer:  # DNxHR: 256x120 at least
        for _ in range(2):
            writer.write(np.zeros(writer.shape, writer.dtype))
    with av.open(str(out)) as written:
        assert written.streams.video[0].codec_context.profile == profile
