"""Probing a clip: what FFmpeg reports of it, or why it is no clip."""

import subprocess

import pytest

from stabilize.video import VideoError, ffmpeg_exe, probe


def test_an_audio_file_is_said_to_be_one(tmp_path):
    # it read "not a video FFmpeg can read"
    audio = tmp_path / "voice.m4a"
    tone = ["-f", "lavfi", "-i", "sine=d=0.5"]
    subprocess.run([ffmpeg_exe(), "-v", "error", *tone, str(audio)], check=True)
    with pytest.raises(VideoError, match=r"voice\.m4a: has no video stream, only audio"):
        probe(audio)
