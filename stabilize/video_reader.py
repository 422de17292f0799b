"""Decoding video with FFmpeg through a pipe (driven with ffmpeg-python).

Probing parses what ``ffmpeg -i`` reports, since the bundled FFmpeg of imageio-ffmpeg
comes without ffprobe.
"""

from __future__ import annotations

import re
import subprocess
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import ffmpeg
import numpy as np
from numpy.typing import NDArray

from stabilize.ffmpeg_tools import ffmpeg_exe, widen_pipe
from stabilize.yuv import pipe_layout


class VideoError(ValueError):
    """The input is missing, not a video, or unreadable; the message is one line."""


@dataclass(frozen=True)
class VideoInfo:
    path: Path | str
    width: int  # as displayed, after the container's rotation
    height: int
    fps: float
    duration: float | None
    rotation: int  # display rotation in degrees, counter-clockwise
    has_audio: bool
    codec: str
    pix_fmt: str
    input_args: tuple = ()  # FFmpeg input options, e.g. an image sequence's start number

    @property
    def size(self) -> tuple[int, int]:
        return (self.height, self.width)


_VIDEO = re.compile(r"Stream #\S+.*?: Video: (\w+).*?, (\w+)(?:\([^)]*\))?, .*?(\d{2,5})x(\d{2,5})")
_FPS = re.compile(r"(\d+(?:\.\d+)?) (?:fps|tbr)")
_DURATION = re.compile(r"Duration: (\d+):(\d+):(\d+(?:\.\d+)?)")
_ROTATION = re.compile(r"rotation of (-?\d+(?:\.\d+)?) degrees|rotate\s*:\s*(-?\d+)")


def sequence_args(path: str | Path, start_number: int | None, fps: float | None) -> tuple:
    """FFmpeg input options for an image sequence (a %d pattern), else none."""
    if "%" not in str(path):
        return ()
    args = ("-f", "image2")
    if start_number is not None:
        args += ("-start_number", str(start_number))
    return (*args, "-framerate", str(fps or 30.0))


def probe(path: str | Path, input_args: tuple = ()) -> VideoInfo:
    """What FFmpeg reports of the first video stream, or :class:`VideoError`.

    ``path`` may be an image-sequence pattern (``frames/img-%d.jpg``) with the input
    options of :func:`sequence_args`.
    """
    pattern = "%" in str(path)
    path = Path(path)
    if not pattern and not path.exists():
        raise VideoError(f"{path}: no such file")
    if path.is_dir():
        raise VideoError(f"{path}: is a folder, not a video (give a pattern like dir/img-%d.jpg)")
    result = subprocess.run(
        [ffmpeg_exe(), "-hide_banner", "-nostdin", *input_args, "-i", str(path)],
        capture_output=True,
        text=True,
        errors="replace",
    )
    text = result.stderr
    video = _VIDEO.search(text)
    if video is None:
        raise VideoError(f"{path}: not a video FFmpeg can read")
    codec, pix_fmt, w, h = video.group(1), video.group(2), int(video.group(3)), int(video.group(4))
    stream_line = text[video.start() : text.find("\n", video.start())]
    fps_match = _FPS.search(stream_line)
    fps = float(fps_match.group(1)) if fps_match else 0.0
    dur = _DURATION.search(text)
    duration = (
        int(dur.group(1)) * 3600 + int(dur.group(2)) * 60 + float(dur.group(3)) if dur else None
    )
    rot = _ROTATION.search(text)
    rotation = int(round(float(rot.group(1) or rot.group(2)))) % 360 if rot else 0
    if rotation in (90, 270):
        w, h = h, w
    has_audio = re.search(r"Stream #\S+.*?: Audio:", text) is not None
    return VideoInfo(
        path, w, h, fps, duration, rotation, has_audio, codec, pix_fmt, tuple(input_args)
    )


def read_frames(
    path: str | Path,
    size: tuple[int, int] | None = None,
    info: VideoInfo | None = None,
    pix_fmt: str = "rgb24",
) -> Iterator[NDArray[np.uint8]]:
    """RGB uint8 frames (H, W, 3), streamed; resized to ``size`` (H, W) if given.
    ``pix_fmt="yuv420p"`` gives I420 frames (3H/2, W) instead (:mod:`stabilize.yuv`), and
    ``"yuv420p10le"`` 10-bit ones (uint16).

    FFmpeg applies the display rotation, so frames come upright. A stream that ends
    early or breaks raises :class:`VideoError` after the frames that did decode.
    """
    info = info or probe(path)
    h, w = size or info.size
    args = info.input_args
    options = {k.lstrip("-"): v for k, v in zip(args[::2], args[1::2], strict=True)}
    shrink = size is not None and size != info.size
    if shrink:
        # Deblocking only smooths detail that the downscale averages away anyway; skipping
        # it makes the decode about 20% faster.
        options["skip_loop_filter"] = "all"
    stream = ffmpeg.input(str(path), **options)
    if shrink:
        stream = stream.filter("scale", w, h, flags="area")
    process = (
        stream.output("pipe:", format="rawvideo", pix_fmt=pix_fmt, fps_mode="passthrough")
        .global_args("-hide_banner", "-loglevel", "error", "-nostdin")
        .run_async(cmd=ffmpeg_exe(), pipe_stdout=True, pipe_stderr=True)
    )
    widen_pipe(process.stdout)
    shape, dtype = pipe_layout(pix_fmt, (h, w))
    frame_bytes = int(np.prod(shape)) * np.dtype(dtype).itemsize
    try:
        while True:
            buf = process.stdout.read(frame_bytes)
            if len(buf) < frame_bytes:
                break
            yield np.frombuffer(buf, dtype).reshape(shape)
    finally:
        process.stdout.close()
        err = process.stderr.read().decode(errors="replace").strip()
        code = process.wait()
    if code != 0:
        last = err.splitlines()[-1] if err else f"exit status {code}"
        raise VideoError(f"{path}: decoding failed: {last}")
    if "partial file" in err:
        raise VideoError(f"{path}: truncated: the file ends before its last frame")


def frame_times(path: str | Path, input_args: tuple = ()) -> np.ndarray:
    """Presentation times (s) of every video frame, from the first, in display order.

    Read from the container's packets (no decoding), so variable frame rate is exact.
    """
    result = subprocess.run(
        [
            ffmpeg_exe(),
            "-hide_banner",
            "-nostdin",
            *input_args,
            "-i",
            str(path),
            "-map",
            "0:v:0",
            "-c",
            "copy",
            "-f",
            "framecrc",
            "-",
        ],
        capture_output=True,
        text=True,
        errors="replace",
    )
    tb = re.search(r"#tb 0: (\d+)/(\d+)", result.stdout)
    if "partial file" in result.stderr:
        raise VideoError(f"{path}: truncated: the file ends before its last frame")
    if result.returncode != 0 or tb is None:
        raise VideoError(f"{path}: cannot read frame timestamps")
    scale = int(tb.group(1)) / int(tb.group(2))
    pts = []
    for line in result.stdout.splitlines():
        if line.startswith("0,"):
            fields = [f.strip() for f in line.split(",")]
            pts.append(int(fields[2]))
    if not pts:
        raise VideoError(f"{path}: no video frames")
    times = np.sort(np.array(pts, dtype=np.float64)) * scale
    return times - times[0]
