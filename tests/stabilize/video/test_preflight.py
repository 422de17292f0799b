"""The checks before any work: an output's container named in the user's words."""

import pytest

from stabilize.video import Encoding
from stabilize.video.preflight import OutputError, check_encoder


@pytest.mark.parametrize(
    ("name", "said"),
    [
        # each named the check's own file, /tmp/stabilize-check.y29r5892/check.xyz
        ("out.xyz", "{out}: .xyz names no container FFmpeg writes: give .mp4, .mov"),
        (
            "out",
            "{out}: no suffix names its container: give .mp4, .mov, .mkv, .webm, … ({out}.mp4)",
        ),
        ("out.mp3", "{out}: .mp3 holds no video (audio only): give .mp4"),  # "no stream"
        ("out.wav", "{out}: .wav holds no video"),
    ],
)
def test_an_output_with_no_video_container_is_named(tmp_path, name, said):
    with pytest.raises(OutputError) as refused:
        check_encoder(tmp_path / name, Encoding(), (64, 64))
    assert str(refused.value).startswith(said.format(out=tmp_path / name))


def test_an_encoder_the_container_refuses_gives_ffmpegs_reason(tmp_path):
    with pytest.raises(OutputError, match=r"as \.webm: .*Only VP8 or VP9 or AV1"):
        check_encoder(tmp_path / "out.webm", Encoding(codec="libx264"), (64, 64))
