"""Encoding frames with FFmpeg through a pipe (driven with ffmpeg-python)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import ffmpeg
import numpy as np
from numpy.typing import NDArray

from stabilize.video.binary import ffmpeg_exe, widen_pipe
from stabilize.video.i420 import pipe_layout


@dataclass(frozen=True)
class Encoding:
    codec: str = "libx264"
    crf: int = 18
    preset: str = "medium"
    pix_fmt: str = "yuv420p"
    threads: int = 0  # encoder threads; 0 lets the encoder choose (all cores)
    b_frames: bool = True  # off for variable-frame-rate output, whose packets are retimed


class FrameWriter:
    """Streams RGB uint8 frames (or I420, with ``pix_fmt_in="yuv420p"``) into an encoder
    process.

    Constant frame rate ``fps``. An optional audio stream (ffmpeg-python) is muxed in:
    copied untouched (``copy_audio``, for a source file's audio) or encoded to AAC and
    cut to the video's length (for a generated tone).
    """

    def __init__(
        self,
        path: str | Path,
        size: tuple[int, int],
        fps: float,
        encoding: Encoding | None = None,
        audio=None,
        *,
        copy_audio: bool = False,
        pix_fmt_in: str = "rgb24",
    ) -> None:
        encoding = encoding or Encoding()
        h, w = size
        self.shape, self.dtype = pipe_layout(pix_fmt_in, size)
        video = ffmpeg.input(
            "pipe:", format="rawvideo", pix_fmt=pix_fmt_in, s=f"{w}x{h}", framerate=fps
        )
        streams = [video] if audio is None else [video, audio]
        options = {
            "vcodec": encoding.codec,
            "crf": encoding.crf,
            "preset": encoding.preset,
            "pix_fmt": encoding.pix_fmt,
            "format": "mp4",
            "movflags": "+faststart",
        }
        if encoding.threads:
            options["threads"] = encoding.threads
        if not encoding.b_frames:
            options["bf"] = 0
        if audio is not None and copy_audio:
            options.update(acodec="copy")
        elif audio is not None:
            options.update(acodec="aac", shortest=None)
        self._process = (
            ffmpeg.output(*streams, str(path), **options)
            .global_args("-hide_banner", "-loglevel", "error", "-nostdin")
            .overwrite_output()
            .run_async(cmd=ffmpeg_exe(), pipe_stdin=True, pipe_stderr=True)
        )
        widen_pipe(self._process.stdin)

    def write(self, frame: NDArray[np.uint8]) -> None:
        if frame.shape != self.shape or frame.dtype != self.dtype:
            want = f"{np.dtype(self.dtype)} {self.shape}"
            raise ValueError(f"frame must be {want}, got {frame.dtype} {frame.shape}")
        self._process.stdin.write(np.ascontiguousarray(frame))  # its buffer, not a copy

    def close(self) -> None:
        self._process.stdin.close()
        err = self._process.stderr.read().decode(errors="replace")
        if self._process.wait() != 0:
            raise RuntimeError(f"ffmpeg failed: {err.strip().splitlines()[-1] if err else '?'}")

    def __enter__(self) -> FrameWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self._process.kill()
            self._process.wait()


def sine_audio(seconds: float, frequency: float = 440.0):
    """A test tone as an ffmpeg-python input (lavfi), for clips that must carry audio."""
    return ffmpeg.input(
        f"sine=frequency={frequency}:duration={seconds:.3f}:sample_rate=48000", format="lavfi"
    ).audio
