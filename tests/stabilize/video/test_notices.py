from dataclasses import replace

import pytest

from stabilize.video import Encoding, VideoInfo
from stabilize.video.notices import (
    bars_notice,
    chroma_notice,
    dolby_vision_notice,
    encoder_notice,
    fields_notice,
    pipe_notices,
    pixels_notice,
)

CLIP = VideoInfo("clip.mp4", 1920, 1080, 30.0, 2.0, 0, True, "h264", "yuv420p")
X264 = Encoding("libx264", 18, pix_fmt="yuv420p")


def test_a_plain_clip_loses_nothing_and_hears_nothing():
    assert pipe_notices(CLIP, X264) == ()
    assert fields_notice(CLIP) == pixels_notice(CLIP) == bars_notice(CLIP) == ()
    assert encoder_notice(X264, "libx264") == ()


@pytest.mark.parametrize(
    ("profile", "said"),
    [
        ("8.4", "its HLG picture is kept"),  # an iPhone's HDR clip
        ("8.1", "its HDR10 picture is kept"),
        ("5.0", "Dolby's own colours, which look wrong"),  # no picture outside it
    ],
)
def test_dolby_vision_left_out_is_said_with_what_its_picture_is(profile, said):
    (notice,) = dolby_vision_notice(profile)
    assert notice.startswith(f"Dolby Vision (profile {profile}) left out") and said in notice
    assert dolby_vision_notice(None) == ()


def test_what_cannot_travel_through_the_pipe_is_named():
    notices = pipe_notices(replace(CLIP, captions=True, alpha=True, pix_fmt="yuva420p"), X264)
    assert len(notices) == 2
    assert notices[0].startswith("closed captions (EIA-608/708")
    assert notices[1].startswith("the source's alpha (transparency, yuva420p) is left out")


def test_depth_lost_names_its_cause():
    deep = replace(CLIP, pix_fmt="yuv420p10le")
    (chosen,) = pipe_notices(deep, X264)
    assert chosen == "yuv420p10le video written at 8 bits: libx264 (yuv420p) holds no more"
    (asked,) = pipe_notices(deep, X264, asked=True)
    assert asked.endswith("as --pix-fmt asks")


def test_finer_colour_written_as_four_two_zero_says_what_keeps_it():
    (notice,) = chroma_notice("yuv422p", X264)
    assert notice.startswith("the source's 4:2:2 colour (yuv422p) is written as 4:2:0 (yuv420p)")
    assert "ProRes, DNxHR" in notice
    assert chroma_notice("yuv422p", replace(X264, pix_fmt="yuv422p")) == ()
    assert chroma_notice("yuv420p", X264) == ()


def test_a_deep_sources_encoder_is_said_with_the_option_that_keeps_the_default():
    (notice,) = encoder_notice(replace(X264, codec="libx265"), "libx264")
    assert notice.startswith("10-bit video: encoded with libx265")
    assert notice.endswith("(--codec libx264 keeps it)")


@pytest.mark.parametrize(
    ("change", "said"),
    [
        (
            {"field_order": "tff", "fields": True, "fps": 50.0},
            "interlaced (top field first): "
            "each field deinterlaced into a frame of its own (FFmpeg's bwdif), 25 → 50",
        ),
        (
            {"field_order": "bff", "deinterlace": True},
            "interlaced (bottom field first): each frame deinterlaced",
        ),
        ({"deinterlace": True}, "flagged progressive: each frame deinterlaced"),
        ({"field_order": "tff"}, "interlaced (top field first), left so (--deinterlace off)"),
    ],
)
def test_fields_are_said_as_they_are_treated(change, said):
    (notice,) = fields_notice(replace(CLIP, **change))
    assert notice.startswith(said)


def test_anamorphic_pixels_are_said_at_the_size_shown():
    info = replace(CLIP, width=1024, height=576, pixel_aspect="16:15", coded=(576, 960))
    (notice,) = pixels_notice(info)
    assert notice.startswith("anamorphic (pixels 16:15): worked on and written in square")
    assert "1024x576" in notice


def test_bars_are_said_on_the_sides_they_lie():
    (letterbox,) = bars_notice(CLIP.within_bars((140, 140, 0, 0)))
    assert letterbox.startswith("black bars (140 and 140 px above and below): the picture")
    (both,) = bars_notice(CLIP.within_bars((8, 8, 240, 240)))
    assert "(8 and 8 px above and below; 240 and 240 px left and right)" in both
