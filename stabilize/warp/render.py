"""Pass 2: decode at full size, warp each frame along the planned path, encode.

Pass 2 stays in I420 from decoder to encoder where the sizes allow (both sides even):
no colour conversion on either side, and half the bytes through the pipes. A clip
decoded as its sensor stored it (:meth:`stabilize.video.VideoInfo.stored`) is turned to
be shown once warped: the output is written upright, with no display rotation.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import replace
from itertools import islice
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from stabilize.progress import Progress, no_progress
from stabilize.settings import Settings
from stabilize.video import FrameWriter, VideoError, VideoInfo, i420, read_frames
from stabilize.video.bars import put_back
from stabilize.video.containers import Container, container_for
from stabilize.video.encode import Encoding, Mux
from stabilize.video.retime import is_variable_rate, retime
from stabilize.video.turn import turn
from stabilize.warp.camera_path import CameraPath
from stabilize.warp.frames import resize_image
from stabilize.warp.planes import resize_planes

WARP_BATCH = 8  # frames warped together on CUDA


def render(
    path: Path,
    out: Path,
    info: VideoInfo,
    planned: CameraPath,
    settings: Settings,
    encoding: Encoding,
    progress: Progress = no_progress,
    mux: Mux | None = None,
) -> int:
    """Decode, warp, encode into the container ``out``'s suffix names, by ``encoding``
    (:func:`output_encoding`, resolved once before any work), with what ``mux`` keeps of
    the source (default: nothing but the video); returns frames written.

    A variable-frame-rate clip is encoded at its nominal rate without B-frames, then its
    packets are restamped with the source's own frame times (:func:`retime`).
    """
    mux = mux or Mux()
    container = container_for(out)
    written = 0
    fps = info.fps or 30.0
    h, w = frame_size(info, settings)
    size = encoded_size(info, settings)
    variable = container.timed and is_variable_rate(planned.times)
    pix_fmt = piped_format(info, settings)
    planar = pix_fmt != "rgb24"
    encoding = replace(encoding, b_frames=False) if variable else encoding
    target = out.with_name(f"{out.stem}.cfr{out.suffix}") if variable else out
    side_by_side = i420.hstack if planar else lambda a, b: np.hstack([a, b])
    resize = resize_planes if planar else resize_image

    def shown(frame: NDArray) -> NDArray:
        """A decoded or warped frame as it is written: framed by its black bars again,
        turned to be shown, then at the output's size."""
        if info.bars:
            frame = put_back(frame, info.bars, planar, info.colour.full_range)
        frame = turn(frame, info.turns, planar, info.mirrored)
        if settings.size:
            return resize(frame, (h, w))
        if (h, w) != info.shown_framed_size:  # odd sides: one row or column off the edge
            return frame[:h, :w]
        return frame

    try:
        with FrameWriter(
            target,
            size,
            fps,
            encoding,
            mux,
            pix_fmt_in=pix_fmt,
            container=container,
            colour=info.colour,
        ) as writer:
            decoded = read_frames(path, info=info, pix_fmt=pix_fmt)
            frames = zip(range(len(planned.zoom)), decoded, strict=False)
            for batch in batches(frames, WARP_BATCH if settings.device == "cuda" else 1):
                for frame, warped in zip(
                    (f for _, f in batch),
                    planned.warp_many(batch, settings.device, info.colour.full_range),
                    strict=True,
                ):
                    warped = shown(warped)
                    writer.write(side_by_side(shown(frame), warped) if settings.preview else warped)
                    written += 1
                    progress(1)
            if written < len(planned.times) - 1:  # the frames after a gap would slip in time
                raise VideoError(
                    f"{path}: {written} frames decoded, where pass 1 read {len(planned.times)}"
                )
        if variable:
            times = planned.times[:written]
            retime(target, out, times, container.muxer, mux.video_delay, container.options)
    finally:
        if variable:
            target.unlink(missing_ok=True)
    return written


def frame_size(info: VideoInfo, settings: Settings) -> tuple[int, int]:
    """(H, W) of each stabilised frame as shown: ``--size``, else the input's (its black
    bars included: :mod:`stabilize.video.bars`) with odd
    sides rounded down (4:2:0 video needs even sides; the last row or column is cropped,
    the smallest loss, and at the frame's edge, which the zoom crops anyway)."""
    h, w = settings.size or info.shown_framed_size
    return h - h % 2, w - w % 2


def piped_format(info: VideoInfo, settings: Settings) -> str:
    """FFmpeg's format of the frames piped to the encoder: I420 at the source's depth (8
    or 10 bits) where the frames' sizes allow, so there are no colour conversions and
    half the bytes travel; else RGB."""
    planar = i420.supports(info.size) and i420.supports(frame_size(info, settings))
    return i420.pipe_format(info.pix_fmt) if planar else "rgb24"


def output_encoding(info: VideoInfo, settings: Settings, container: Container) -> Encoding:
    """The encoder and pixel format the output is written with: ``--codec``, else the
    container's default for the source's depth (:meth:`Encoding.for_frames`)."""
    return settings.encoding.for_frames(container, piped_format(info, settings))


def encoded_size(info: VideoInfo, settings: Settings) -> tuple[int, int]:
    """(H, W) of the encoded frames: the stabilised frame, twice as wide in a preview."""
    h, w = frame_size(info, settings)
    return (h, 2 * w) if settings.preview else (h, w)


def batches(items: Iterable, n: int) -> Iterator[list]:
    """Consecutive lists of n items (the last may be shorter)."""
    it = iter(items)
    while batch := list(islice(it, n)):
        yield batch
