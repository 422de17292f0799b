"""The checks before any work: an output's container named in the user's words."""

import pytest

from stabilize.video import Encoding, probe
from stabilize.video.containers import container_for
from stabilize.video.preflight import OutputError, check_encoder, check_streams
from stabilize.video.streams import keep_streams
from tests.stabilize.helpers import SAMPLE


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


def test_tracks_the_container_cannot_hold_are_refused_before_any_work(tmp_path):
    # AAC audio in MXF failed once the work was done: "the encoder failed: pcm_rechunk"
    info = probe(SAMPLE / "clip.mp4")
    for name, holds in (("out.mxf", False), ("out.mp4", True), ("out.mkv", True)):
        mux = keep_streams(info, container_for(name), info.video_delay)
        if holds:
            check_streams(tmp_path / name, Encoding(), info.size, mux)
            continue
        with pytest.raises(OutputError, match=r"tracks cannot go into \.mxf as they are"):
            check_streams(tmp_path / name, Encoding(), info.size, mux)
    assert not list(tmp_path.iterdir())  # the check writes beside nothing
