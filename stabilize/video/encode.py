"""Encoding frames with FFmpeg through a pipe, into the container the output names.

The frames arrive raw on FFmpeg's standard input (input 0); a :class:`Mux` adds the other
inputs and says which of their streams go into the output and how (input 1 is the source
clip, whose audio, subtitles, chapters and metadata are kept:
:func:`stabilize.video.streams.keep_streams`).
"""

from __future__ import annotations

import subprocess
import weakref
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from stabilize.video.binary import drain, ffmpeg_exe, interrupts_held, local, widen_pipe
from stabilize.video.colour import UNKNOWN, Colour
from stabilize.video.containers import Container, container_for
from stabilize.video.encoders import (
    DEFAULT_PRESET,
    EDITING_FULL_PIX_FMT,
    EDITING_PIX_FMT,
    FRAME_CLOCKED,
    encoder_args,
)
from stabilize.video.i420 import chroma, is_deep, pipe_format, pipe_layout


class EncodeError(RuntimeError):
    """The encoder failed while working; the message is FFmpeg's own last line."""


@dataclass(frozen=True)
class Encoding:
    """How the video stream is encoded. ``codec`` None: the container's default encoder
    (libx264, or VP9 for WebM; for a source of 10 bits or more, HEVC: :meth:`for_frames`);
    ``crf`` None: that encoder's default quality (x264: 18)."""

    codec: str | None = None
    crf: int | None = None
    preset: str = DEFAULT_PRESET
    # what is written (FFmpeg's name); None: chosen by :meth:`for_frames`, 4:2:0 at the
    # source's depth, which every player plays
    pix_fmt: str | None = None
    threads: int = 0  # encoder threads; 0 lets the encoder choose (all cores)
    b_frames: bool = True  # off for variable-frame-rate output, whose packets are retimed

    def codec_for(self, container: Container) -> str:
        """The encoder to use in ``container``."""
        return self.codec or container.video_encoder

    def for_frames(self, container: Container, pix_fmt_in: str, source: str = "") -> Encoding:
        """This encoding made whole for frames piped as ``pix_fmt_in`` into ``container``,
        from a source of pixel format ``source`` (FFmpeg's name; "": unknown).

        A 10-bit pipe (``yuv420p10le``, or 16-bit RGB, ``rgb48le``) is encoded at 10
        bits, by the container's encoder for deep sources where none is asked for: HEVC
        in MP4, MOV, MKV and TS, since H.264 at 10 bits plays neither on Apple's devices
        nor in most browsers. Frames are written as 4:2:0, which every player plays,
        unless a pixel format is asked for or the encoder is an editing codec, which
        writes its own 4:2:2 (:data:`~stabilize.video.encoders.EDITING_PIX_FMT`), or its
        4:4:4 from a 4:4:4 or RGB source. An image sequence's pictures take their
        format's pixels (16 bits a channel in PNG and TIFF for a deep source).

        >>> from stabilize.video.containers import container_for
        >>> deep = Encoding().for_frames(container_for("a.mov"), "yuv420p10le")
        >>> deep.codec, deep.pix_fmt
        ('libx265', 'yuv420p10le')
        >>> Encoding().for_frames(container_for("a.mov"), "yuv420p").codec
        'libx264'
        >>> Encoding(codec="libx264").for_frames(container_for("a.mov"), "yuv420p10le").codec
        'libx264'
        >>> Encoding().for_frames(container_for("a.mkv"), "rgb48le").pix_fmt
        'yuv420p10le'
        >>> Encoding(codec="prores_ks").for_frames(container_for("a.mov"), "rgb24").pix_fmt
        'yuv422p10le'
        >>> Encoding(codec="dnxhd").for_frames(container_for("a.mxf"), "rgb24", "gbrp").pix_fmt
        'yuv444p10le'
        >>> Encoding().for_frames(container_for("f/%05d.png"), "yuv420p10le").pix_fmt
        'rgb48be'
        >>> asked = Encoding(pix_fmt="yuv422p10le").for_frames(container_for("a.mov"), "yuv420p")
        >>> asked.codec, asked.pix_fmt
        ('libx265', 'yuv422p10le')
        >>> Encoding(pix_fmt="yuv420p").for_frames(container_for("a.mov"), "yuv420p10le").codec
        'libx264'
        """
        deep = is_deep(pix_fmt_in)
        if container.pix_fmt:  # the encoder's own (GIF's palette)
            return replace(self, codec=self.codec_for(container), pix_fmt=container.pix_fmt)
        if self.pix_fmt is not None:  # asked for (--pix-fmt): its depth, not the source's
            deep = is_deep(self.pix_fmt)
        if container.pictures:  # an image sequence's: RGB, or JPEG's full-range YUV
            pix_fmt = self.pix_fmt or container.pictures[deep]
            return replace(self, codec=self.codec_for(container), pix_fmt=pix_fmt)
        codec = self.codec or (container.deep_encoder if deep else None) or container.video_encoder
        if self.pix_fmt is not None:
            return replace(self, codec=codec)
        if codec in EDITING_PIX_FMT and chroma(source) == "4:4:4":
            return replace(self, codec=codec, pix_fmt=EDITING_FULL_PIX_FMT)
        if codec in EDITING_PIX_FMT:
            return replace(self, codec=codec, pix_fmt=EDITING_PIX_FMT[codec][deep])
        return replace(self, codec=codec, pix_fmt=pipe_format(pix_fmt_in))


@dataclass(frozen=True)
class Mux:
    """What goes into the output beside the piped video: extra FFmpeg inputs (input 1
    on), the arguments that map and encode their streams, what was changed or left out
    (``notices``), and how late the video starts after the source's first stream (s)."""

    inputs: tuple[tuple[str, ...], ...] = ()
    args: tuple[str, ...] = ()
    notices: tuple[str, ...] = ()
    video_delay: float = 0.0


def output_args(
    path: str | Path, encoding: Encoding, container: Container | None = None, delay: float = 0.0
) -> list[str]:
    """The video encoder's and the container's arguments for an output ``path``, the
    video started ``delay`` s late (:attr:`Mux.video_delay`)."""
    container = container or container_for(path)
    codec = encoding.codec_for(container)
    pix_fmt = encoding.pix_fmt or "yuv420p"
    deep = is_deep(pix_fmt)
    full = chroma(pix_fmt) == "4:4:4"
    args = [*encoder_args(codec, encoding.crf, encoding.preset, deep, full), "-pix_fmt", pix_fmt]
    if encoding.threads:
        args += ["-threads", str(encoding.threads)]
    if not encoding.b_frames:
        args += ["-bf", "0"]
    if container.keyframes:
        args += ["-g", str(container.keyframes)]
    if container.hevc_tag and codec in ("libx265", "hevc"):
        args += ["-tag:v", container.hevc_tag]
    fine = container.fine_clock and codec not in FRAME_CLOCKED
    args += list(container.options) + _filters(delay, container.video_filter, fine)
    return [*args, "-f", container.muxer] if container.muxer else args


DELAY_CLOCK = 90_000  # ticks per second of a delayed video's timestamps (MPEG's clock)


def _filters(delay: float, chain: str, fine: bool = True) -> list[str]:
    """The video's one filter graph: ``chain`` (the container's), after a shift that
    starts the piped video ``delay`` s late, on a 90 kHz clock (``fine``): the pipe's own
    clock ticks in whole frames, which would round a 21 ms delay to 33. Where the
    encoder or the muxer cannot take that clock (``fine`` False), the delay is rounded
    to whole frames."""
    if abs(delay) <= 5e-4:
        return ["-filter:v", chain] if chain else []
    shift = f"settb=1/{DELAY_CLOCK},setpts=PTS+{delay:.6f}/TB"
    graph = f"{shift},{chain}" if chain else shift
    clock = ["-enc_time_base:v", f"1:{DELAY_CLOCK}"] if fine else []
    return ["-filter:v", graph, *clock]


class FrameWriter:
    """Streams RGB uint8 frames (uint16 with ``pix_fmt_in="rgb48le"``, or I420 with
    ``"yuv420p"`` or ``"yuv420p10le"``) into an encoder process at a constant frame rate
    ``fps``, muxed with what ``mux`` adds, tagged with the source's ``colour`` (I420
    frames are taken to be in it already; RGB ones are converted to it)."""

    def __init__(
        self,
        path: str | Path,
        size: tuple[int, int],
        fps: float,
        encoding: Encoding | None = None,
        mux: Mux | None = None,
        *,
        pix_fmt_in: str = "rgb24",
        container: Container | None = None,
        colour: Colour | None = None,
    ) -> None:
        encoding, mux = encoding or Encoding(), mux or Mux()
        colour = colour or UNKNOWN
        h, w = size
        self.path = Path(path)
        self.shape, self.dtype = pipe_layout(pix_fmt_in, size)
        raw = ["-f", "rawvideo", "-pix_fmt", pix_fmt_in, "-s", f"{w}x{h}", "-framerate", str(fps)]
        cmd = [ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-nostdin", "-y"]
        # YUV samples are the source's own: stated on the pipe, they are not converted.
        # RGB ones have no range or matrix, but FFmpeg drops primaries and transfer that
        # the output alone states when it converts.
        piped = colour if pix_fmt_in.startswith("yuv") else replace(colour, range=None, matrix=None)
        cmd += [*raw, *piped.ffmpeg_args(), "-i", "pipe:"]
        for extra in mux.inputs:
            cmd += list(extra)
        # the video is the track players show: Matroska otherwise marks it not the default
        cmd += ["-map", "0:v", "-disposition:v:0", "default", *mux.args]
        container = container or container_for(path)
        codec = encoding.codec_for(container)
        cmd += [*output_args(path, encoding, container, mux.video_delay), *colour.ffmpeg_args()]
        cmd += [*colour.hdr10_args(codec), local(path, container.pictures is not None)]
        process = None
        try:
            with interrupts_held():  # one inside Popen left FFmpeg running, unowned
                process = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
            self._process = process
            # An interrupt after this returns and before `with` takes the writer (it
            # strikes as __enter__ starts, and a `with` whose __enter__ raised never calls
            # __exit__) left FFmpeg running, to write its file after the caller had
            # removed it (a test of SIGTERM found a .partial.cfr.mp4 left): the writer,
            # once dropped, reaps it.
            weakref.finalize(self, _reap, process)
            self._said = drain(process.stderr)  # (a damaged source's audio says much)
            widen_pipe(process.stdin)
        except BaseException:  # an interrupt before `with` takes it: FFmpeg left running
            if process is not None:
                _reap(process)  # wrote its file after the caller had removed it
            raise

    def write(self, frame: NDArray[np.uint8]) -> None:
        if frame.shape != self.shape or frame.dtype != self.dtype:
            want = f"{np.dtype(self.dtype)} {self.shape}"
            raise ValueError(f"frame must be {want}, got {frame.dtype} {frame.shape}")
        try:
            self._process.stdin.write(np.ascontiguousarray(frame))  # its buffer, not a copy
        except (BrokenPipeError, OSError):
            raise self._failure() from None

    def close(self) -> None:
        try:
            self._process.stdin.close()
        except (BrokenPipeError, OSError):
            pass
        try:
            code = self._process.wait()
        except BaseException:  # an interrupt while FFmpeg finishes the file: left running,
            self._stop()  # it would write it again after the caller removed it (MP4's
            raise  # faststart pass reopens it by name)
        if code != 0:
            raise self._failure()
        self._said()

    def _failure(self) -> EncodeError:
        """The encoder's death as one line: its last message, the disk's state named."""
        self._process.kill()
        err = self._said()
        self._process.wait()
        return EncodeError(encoder_message(err, self._process.returncode))

    def _stop(self) -> None:
        """End the encoder at once and reap it: nothing it would write is wanted."""
        _reap(self._process)

    def __enter__(self) -> FrameWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self._stop()


def _reap(process: subprocess.Popen) -> None:
    """End an encoder still running when its writer is dropped: nothing it would write
    is wanted (a writer closed or stopped has nothing left to reap)."""
    if process.poll() is None:
        process.kill()
        process.wait()


def encoder_message(stderr: str, code: int | None) -> str:
    """FFmpeg's failure in one line: its first message (the cause; the later ones are
    its threads winding down), and 'the disk is full' where it says so."""
    first = stderr.splitlines()[0] if stderr else f"exit status {code}"
    if "No space left on device" in stderr:
        return f"the disk is full (FFmpeg: {first})"
    return f"the encoder failed: {first}"


def sine_audio(seconds: float, frequency: float = 440.0) -> Mux:
    """A test tone as a second input, encoded to AAC and cut to the video's length, for
    rendered clips that must carry audio."""
    tone = f"sine=frequency={frequency}:duration={seconds:.3f}:sample_rate=48000"
    return Mux((("-f", "lavfi", "-i", tone),), ("-map", "1:a", "-c:a", "aac", "-shortest"))
