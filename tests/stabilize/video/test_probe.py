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


def test_a_song_with_its_cover_picture_is_said_to_be_audio(tmp_path):
    # its cover is a video stream of one picture: "has 1 frame(s); nothing to stabilise"
    song = tmp_path / "song.m4a"
    cmd = [ffmpeg_exe(), "-v", "error", "-f", "lavfi", "-i", "sine=d=0.5", "-f", "lavfi"]
    cmd += ["-i", "testsrc=s=64x64", "-frames:v", "1", "-map", "0", "-map", "1", "-c:v", "png"]
    subprocess.run([*cmd, "-disposition:v", "attached_pic", str(song)], check=True)
    with pytest.raises(VideoError, match=r"song\.m4a: has no video stream, only audio and a cover"):
        probe(song)


@pytest.mark.parametrize(("rate", "fps"), [("24000/1001", 24000 / 1001), ("25", 25.0)])
def test_an_ntsc_frame_rate_is_read_whole(tmp_path, rate, fps):
    # FFmpeg lists 24000/1001 as "23.98": written at 23.98, the video ran ahead of the
    # audio by 0.1 s every 10 minutes
    clip = tmp_path / "ntsc.mp4"
    frames = ["-f", "lavfi", "-i", f"color=black:s=64x64:r={rate}", "-frames:v", "3"]
    subprocess.run([ffmpeg_exe(), "-v", "error", *frames, str(clip)], check=True)
    assert probe(clip).fps == fps
