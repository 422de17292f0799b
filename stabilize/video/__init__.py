"""Video in and out, through FFmpeg: probing, decoding, encoding, I420 planes, retiming.

This layer knows nothing of rotations, paths or warps; everything above it reads and
writes video through these names.
"""

from stabilize.video.atomic import atomic_output
from stabilize.video.binary import ffmpeg_exe
from stabilize.video.decode import frame_interval, frame_times, read_frames
from stabilize.video.encode import Encoding, FrameWriter
from stabilize.video.probe import VideoError, VideoInfo, probe
from stabilize.video.retime import is_variable_rate, retime
from stabilize.video.sequence import sequence_args

__all__ = [
    "Encoding",
    "FrameWriter",
    "VideoError",
    "VideoInfo",
    "atomic_output",
    "ffmpeg_exe",
    "frame_interval",
    "frame_times",
    "is_variable_rate",
    "probe",
    "read_frames",
    "retime",
    "sequence_args",
]
