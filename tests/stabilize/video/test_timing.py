"""Frame times from any container, constant rates on millisecond clocks, and audio that
stays in sync with a video that starts after it."""

from __future__ import annotations

import subprocess
from pathlib import Path

import av
import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.video import Encoding, ffmpeg_exe, frame_times, probe, read_frames
from stabilize.video.retime import is_variable_rate


def transcode(src: Path, out: Path, *args: str) -> Path:
    subprocess.run([ffmpeg_exe(), "-v", "error", "-y", "-i", str(src), *args, str(out)], check=True)
    return out


def av_offset(path: Path) -> float:
    """How late the video starts after the audio, s."""
    with av.open(str(path)) as c:
        v, a = c.streams.video[0], c.streams.audio[0]
        return float(v.start_time * v.time_base) - float(a.start_time * a.time_base)


def test_avi_without_packet_times_takes_the_decoded_frames_times(shaky, tmp_path):
    avi = transcode(shaky, tmp_path / "x.avi", "-c:v", "mpeg4", "-bf", "2", "-c:a", "mp3")
    times = frame_times(avi)
    assert len(times) == 60 and np.isfinite(times).all()
    np.testing.assert_allclose(np.diff(times), 1 / 30, atol=1e-9)


def test_a_millisecond_clock_is_a_constant_rate(shaky, tmp_path):
    mkv = transcode(shaky, tmp_path / "x.mkv", "-c", "copy")
    times = frame_times(mkv)
    assert set(np.round(np.diff(times), 3)) == {0.033, 0.034}  # rounded to 1 ms
    assert not is_variable_rate(times)
    jittery = np.arange(60) / 30 + np.where(np.arange(60) % 2, 0.006, 0.0)
    assert is_variable_rate(jittery)


@pytest.fixture(scope="module")
def late_video(shaky, tmp_path_factory) -> Path:
    """A TS whose video starts 21 ms after its audio, as broadcast recordings do."""
    folder = tmp_path_factory.mktemp("late")
    audio = transcode(shaky, folder / "a.m4a", "-vn", "-c:a", "copy")
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shaky), "-itsoffset", "-0.021"]
    cmd += ["-i", str(audio), "-map", "0:v", "-map", "1:a", "-c", "copy", "-f", "mpegts"]
    ts = folder / "late.ts"
    subprocess.run([*cmd, str(ts)], check=True)
    return ts


@pytest.mark.parametrize("suffix", [".ts", ".mkv", ".mp4"])
def test_audio_stays_in_sync_within_a_millisecond(late_video, tmp_path, suffix):
    source = (
        late_video
        if suffix == ".ts"
        else transcode(late_video, tmp_path / f"in{suffix}", "-c", "copy")
    )
    before = av_offset(source)
    assert before > 0.015 and probe(source).video_delay == pytest.approx(before, abs=1e-3)
    out = tmp_path / f"out{suffix}"
    stabilize_video(source, out, Settings(fov=70.0))
    assert av_offset(out) == pytest.approx(before, abs=1e-3)


def test_a_clip_trimmed_without_re_encoding_keeps_the_frames_it_shows(shaky, tmp_path):
    # `-ss` before `-c copy` keeps the packets from the keyframe before the cut, and an
    # edit list that discards them: they decode, but no player shows them
    trimmed = tmp_path / "trimmed.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-ss", "0.5", "-i", str(shaky), "-c", "copy"]
    subprocess.run([*cmd, str(trimmed)], check=True)
    shown = sum(1 for _ in read_frames(trimmed))
    times = frame_times(trimmed)
    assert shown == len(times) == 45 and times[0] == 0
    np.testing.assert_allclose(np.diff(times), 1 / 30, atol=1e-6)
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(trimmed, out, Settings(fov=70.0))
    assert summary["frames"] == 45 and probe(out).has_audio
    np.testing.assert_allclose(frame_times(out), times, atol=1e-3)
    assert av_offset(out) == pytest.approx(av_offset(trimmed), abs=1e-3)


@pytest.mark.parametrize(("suffix", "codec"), [(".mpg", None), (".mkv", "mpeg2video")])
def test_mpeg2_and_mpeg_ps_take_a_late_video_within_a_frame(late_video, tmp_path, suffix, codec):
    # MPEG-2's encoder opens on no 90 kHz clock (its delay's, before: "MPEG-1/2 does not
    # support 90000/1 fps", after all the work), and MPEG-PS's muxer padded H.264 on one
    # to 24 MB for 2 s, for minutes; .mpg was H.264, which no DVD player reads
    out = tmp_path / f"out{suffix}"
    settings = Settings(fov=70.0, encoding=Encoding(codec=codec))
    summary, _ = stabilize_video(late_video, out, settings)
    assert probe(out).codec == "mpeg2video" and summary["frames"] == 60
    assert out.stat().st_size < 2_000_000  # 2 s of 640×360 at quantiser 2: about 0.8 MB
    assert abs(av_offset(out) - av_offset(late_video)) < 1 / 60  # to the nearer frame
    np.testing.assert_allclose(frame_times(out), frame_times(late_video), atol=1 / 60)
