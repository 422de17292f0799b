"""The checks before any work: an output's container named in the user's words."""

import numpy as np
import pytest

from stabilize.video import Encoding, probe
from stabilize.video.containers import container_for
from stabilize.video.preflight import OutputError, check_encoder, check_streams, check_times
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
    # AAC audio in MXF failed once the work was done: "the encoder failed: pcm_rechunk";
    # a raw H.264 stream holds no audio at all
    info = probe(SAMPLE / "clip.mp4")
    for name, holds in (("out.h264", False), ("out.mp4", True), ("out.mxf", True)):
        mux = keep_streams(info, container_for(name), info.video_delay)
        if holds:
            check_streams(tmp_path / name, Encoding(), info.size, mux)
            continue
        with pytest.raises(OutputError, match=r"tracks cannot go into \.h264 as they are"):
            check_streams(tmp_path / name, Encoding(), info.size, mux)
    assert not list(tmp_path.iterdir())  # the check writes beside nothing


def test_a_frame_rate_mxf_cannot_hold_is_refused_before_any_work(tmp_path):
    # a 15 fps clip failed once pass 1 was done ("Unsupported frame rate 15/1")
    check_encoder(tmp_path / "out.mxf", Encoding(), (64, 64), 24000 / 1001)
    with pytest.raises(OutputError, match=r"out\.mxf: \.mxf holds broadcast frame rates alone "):
        check_encoder(tmp_path / "out.mxf", Encoding(), (64, 64), 15.0)
    check_encoder(tmp_path / "out.mov", Encoding(), (64, 64), 15.0)


def test_a_variable_rate_is_refused_where_the_container_holds_one_rate(tmp_path):
    steady = np.arange(90) / 30.0
    varied = steady + np.where(np.arange(90) % 3 == 1, 0.012, 0.0)  # a phone's 30 fps
    check_times(tmp_path / "out.mxf", steady)
    check_times(tmp_path / "out.mp4", varied)  # remuxed at each frame's time
    with pytest.raises(OutputError, match=r"MXF holds one constant frame rate, and this clip"):
        check_times(tmp_path / "out.mxf", varied)
