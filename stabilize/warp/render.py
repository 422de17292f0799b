"""Pass 2: decode at full size, warp each frame along the planned path, encode.

Pass 2 stays in I420 from decoder to encoder where the sizes allow (both sides even):
no colour conversion on either side, and half the bytes through the pipes. Colour finer
than 4:2:0, bound for an encoder that keeps it, travels as RGB (:func:`piped_format`).
A clip decoded as its sensor stored it (:meth:`stabilize.video.VideoInfo.stored`) is turned to
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
from stabilize.video.retime import is_variable_rate, retime, thinned
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
    packets are restamped with the source's own frame times (:func:`retime`). Frames the
    container's players cannot show are left out (:func:`shown_frames`: a GIF's).
    """
    mux = mux or Mux()
    container = container_for(out)
    written, decoded_count = 0, 0
    fps = info.fps or 30.0
    h, w = frame_size(info, settings)
    size = encoded_size(info, settings)
    shown = shown_frames(planned.times, container)
    times = planned.times[shown]
    variable = container.timed and is_variable_rate(times)
    if len(times) < len(planned.times) and not variable:  # every k-th frame
        fps = (len(times) - 1) / (times[-1] - times[0])
    pix_fmt = piped_format(info, settings, container)
    planar = pix_fmt.startswith("yuv")
    encoding = replace(encoding, b_frames=False) if variable else encoding
    target = out.with_name(f"{out.stem}.cfr{out.suffix}") if variable else out
    side_by_side = i420.hstack if planar else lambda a, b: np.hstack([a, b])
    resize = resize_planes if planar else resize_image

    def as_written(frame: NDArray) -> NDArray:
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
            kept = np.isin(np.arange(len(planned.zoom)), shown)

            def frames() -> Iterator[tuple[int, NDArray]]:
                nonlocal decoded_count
                for k, frame in zip(range(len(planned.zoom)), decoded, strict=False):
                    decoded_count += 1
                    if kept[k]:
                        yield k, frame
                    else:  # left out where the container's players cannot show it
                        progress(1)

            for batch in batches(frames(), WARP_BATCH if settings.device == "cuda" else 1):
                for frame, warped in zip(
                    (f for _, f in batch),
                    planned.warp_many(
                        batch, settings.device, info.colour.full_range, settings.border
                    ),
                    strict=True,
                ):
                    warped = as_written(warped)
                    writer.write(
                        side_by_side(as_written(frame), warped) if settings.preview else warped
                    )
                    written += 1
                    progress(1)
            if decoded_count < len(planned.times) - 1:  # the frames after a gap would slip
                raise VideoError(
                    f"{path}: {decoded_count} frames decoded, where pass 1 read "
                    f"{len(planned.times)}"
                )
        if variable:
            stamps = times[:written]
            retime(target, out, stamps, container.muxer, mux.video_delay, container.options)
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


def check_shape(info: VideoInfo, settings: Settings, tolerance: float = 0.01) -> None:
    """ValueError where ``--size`` is not the picture's shape (beyond ``tolerance`` of
    its aspect ratio): it was stretched to it, a phone's upright 720x1280 clip to 1280x720.
    """
    if not settings.size:
        return
    (h, w), (sh, sw) = settings.size, info.shown_framed_size
    if abs((w / h) / (sw / sh) - 1.0) <= tolerance:
        return
    h_for_w, w_for_h = 2 * round(w * sh / sw / 2), 2 * round(h * sw / sh / 2)
    raise ValueError(
        f"--size {w}x{h} would stretch the {sw}x{sh} picture: give its shape, e.g. "
        f"{w}x{h_for_w} or {w_for_h}x{h}"
    )


def shown_frames(times: NDArray, container: Container) -> NDArray[np.intp]:
    """The frames written into ``container``: all, but where its players show no frame
    sooner than its ``min_interval`` after the last (GIF's 20 ms in browsers: a 60 fps
    clip's every other frame, :func:`stabilize.video.retime.thinned`)."""
    if not container.min_interval:
        return np.arange(len(times))
    return thinned(times, container.min_interval)


def shown_notice(times: NDArray, container: Container) -> tuple[str, ...]:
    """A notice where some frames are left out for the container's players."""
    shown = len(shown_frames(times, container))
    if shown == len(times):
        return ()
    return (
        f"{container.name} frames shorter than {1000 * container.min_interval:.0f} ms are "
        f"shown for 100 ms in browsers: {shown} of {len(times)} frames are written, each at "
        "its own time",
    )


def piped_format(info: VideoInfo, settings: Settings, container: Container) -> str:
    """FFmpeg's format of the frames piped to the encoder into ``container``: I420 at the
    source's depth (8 or 10 bits), so there are no colour conversions and half the bytes
    travel; else RGB at its depth (8 or 16 bits a channel), where a side is odd, or where
    the source's colour is finer than 4:2:0 (a camera's or ProRes's 4:2:2, 4:4:4, RGB
    pictures) and the encoder keeps colour that fine (ProRes, DNxHR, PNG or TIFF
    pictures, a GIF's palette): I420 would halve it on the way."""
    planar, rgb = i420.pipe_format(info.pix_fmt), i420.rgb_pipe(info.pix_fmt)
    if not (i420.supports(info.size) and i420.supports(frame_size(info, settings))):
        return rgb
    written = settings.encoding.for_frames(container, planar, info.pix_fmt).pix_fmt
    fine = i420.finer(info.pix_fmt, planar) and i420.finer(written, planar)
    return rgb if fine else planar


def output_encoding(info: VideoInfo, settings: Settings, container: Container) -> Encoding:
    """The encoder and pixel format the output is written with: ``--codec``, else the
    container's default for the source's depth (:meth:`Encoding.for_frames`)."""
    piped = piped_format(info, settings, container)
    return settings.encoding.for_frames(container, piped, info.pix_fmt)


def encoded_size(info: VideoInfo, settings: Settings) -> tuple[int, int]:
    """(H, W) of the encoded frames: the stabilised frame, twice as wide in a preview."""
    h, w = frame_size(info, settings)
    return (h, 2 * w) if settings.preview else (h, w)


def batches(items: Iterable, n: int) -> Iterator[list]:
    """Consecutive lists of n items (the last may be shorter)."""
    it = iter(items)
    while batch := list(islice(it, n)):
        yield batch
