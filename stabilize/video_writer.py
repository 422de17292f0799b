"""Encoding frames with FFmpeg through a pipe (driven with ffmpeg-python)."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import ffmpeg
import numpy as np
from numpy.typing import NDArray

from stabilize.ffmpeg_tools import ffmpeg_exe, widen_pipe
from stabilize.yuv import pipe_layout

TIMESCALE = 90_000  # ticks per second of retimed video (MPEG's clock)


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


def is_variable_rate(times: NDArray, tolerance: float = 0.01) -> bool:
    """Whether frame intervals differ from their median by more than ``tolerance`` of it."""
    steps = np.diff(np.asarray(times, dtype=np.float64))
    if steps.size < 2:
        return False
    median = float(np.median(steps))
    return bool(np.max(np.abs(steps - median)) > tolerance * median)


def retime(src: str | Path, dst: str | Path, times: NDArray) -> None:
    """Copy ``src`` (written at a constant rate, without B-frames) to ``dst`` with the
    video frames stamped at ``times`` (s, one per frame); other streams are copied as they
    are. No re-encoding: the packets are remuxed with new timestamps.

    FFmpeg's command line cannot take per-frame timestamps for frames arriving through a
    pipe, so this step uses PyAV (FFmpeg's libraries) to rewrite them.
    """
    import av

    times = np.asarray(times, dtype=np.float64) - float(times[0])
    ticks = np.round(times * TIMESCALE).astype(np.int64)
    step = np.arange(len(ticks))
    ticks = np.maximum.accumulate(ticks - step) + step  # strictly rising, as a muxer needs
    last = np.median(np.diff(ticks)) if len(ticks) > 1 else TIMESCALE // 30
    gaps = np.diff(ticks, append=ticks[-1] + last)
    with av.open(str(src)) as inp, av.open(str(dst), "w", format="mp4") as out:
        video = inp.streams.video[0]
        streams = {s.index: out.add_stream_from_template(s) for s in inp.streams}
        streams[video.index].time_base = Fraction(1, TIMESCALE)
        k = 0  # without B-frames, packets come in display order: the k-th is frame k
        for packet in inp.demux():
            if packet.dts is None:  # a demuxer's flush packet
                continue
            if packet.stream is video:
                if k >= len(ticks):
                    raise RuntimeError(f"{src}: more frames than the {len(ticks)} timestamps")
                packet.time_base = Fraction(1, TIMESCALE)
                packet.pts = packet.dts = int(ticks[k])
                packet.duration = int(gaps[k])
                k += 1
            packet.stream = streams[packet.stream.index]
            out.mux(packet)
