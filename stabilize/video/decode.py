"""Decoding video with FFmpeg through a pipe (driven with ffmpeg-python), and reading
each frame's presentation time from the container's packets."""

from __future__ import annotations

import re
import subprocess
from collections.abc import Iterator
from pathlib import Path

import ffmpeg
import numpy as np
from numpy.typing import NDArray

from stabilize.video.binary import drain, ffmpeg_exe, local, widen_pipe
from stabilize.video.fields import deinterlace_filter, interlaced
from stabilize.video.i420 import pipe_layout
from stabilize.video.probe import VideoError, VideoInfo, probe
from stabilize.video.sequence import is_pattern

# The input's name while ffmpeg-python composes the command, which hashes every argument
# as UTF-8: a name that is not (a Latin-1 name off an old card, caf\xe9.mp4) failed it
STAND_IN = "<the input>"
# FFmpeg's filters that turn a frame counter-clockwise by a display rotation (degrees)
TURN_FILTERS = {
    90: (("transpose", "cclock"),),
    180: (("hflip", None), ("vflip", None)),
    270: (("transpose", "clock"),),
}


def read_frames(
    path: str | Path,
    size: tuple[int, int] | None = None,
    info: VideoInfo | None = None,
    pix_fmt: str = "rgb24",
) -> Iterator[NDArray[np.uint8]]:
    """RGB uint8 frames (H, W, 3), streamed; resized to ``size`` (H, W) if given.
    ``pix_fmt="yuv420p"`` gives I420 frames (3H/2, W) instead (:mod:`stabilize.yuv`), and
    ``"yuv420p10le"`` 10-bit ones (uint16).

    FFmpeg applies the display rotation, so frames come upright, unless ``info`` is
    :meth:`VideoInfo.stored`: they then come as the sensor stored them. An interlaced
    stream's frames come deinterlaced, one for each frame, unless ``info`` is
    :meth:`VideoInfo.deinterlaced` ``("off")`` (:mod:`stabilize.video.fields`). A stream
    that ends early or breaks raises :class:`VideoError` after the frames that did decode.
    """
    info = info or probe(path)
    h, w = size or info.size
    args = info.input_args
    options = {k.lstrip("-"): v for k, v in zip(args[::2], args[1::2], strict=True)}
    # An image sequence's EXIF orientation is turned here, the same on every FFmpeg: some
    # versions turn it (9.0 does, frame by frame), others leave it
    exif_turn = info.autorotate and (info.rotation or info.mirror) and is_pattern(path)
    if not info.autorotate or exif_turn:
        options["noautorotate"] = None
    dh, dw = info.decoded_size
    shrink = (h, w) != (dh, dw) and h <= dh and w <= dw
    if shrink and size is not None:
        # Deblocking only smooths detail that the downscale to a working size averages
        # away anyway; skipping it makes the decode about 20% faster. (Not where only an
        # anamorphic stream's pixels are narrowed, DV's 720 to 640: that is the output.)
        options["skip_loop_filter"] = "all"
    # the first video stream, as probe lists it: FFmpeg's own choice is the largest, and
    # a dashcam's front camera after its smaller rear one was read at the rear's size
    stream = ffmpeg.input(STAND_IN, **options)["v:0"]
    if exif_turn:
        mirror = (("hflip", None),) if info.mirror else ()
        for name, value in (*mirror, *TURN_FILTERS.get(info.rotation, ())):
            stream = stream.filter(name, value) if value else stream.filter(name)
    if info.deinterlace:  # before any scaling, which would blend the fields
        every = not interlaced(info.field_order)
        name, fields = deinterlace_filter(every_frame=every, fields=info.fields)
        stream = stream.filter(name, **fields)
    source = (dh, dw)
    if info.bars:  # the picture inside them, in square pixels
        fh, fw = info.framed_size
        if (fh, fw) != source:
            stream = stream.filter("scale", fw, fh, flags="bicubic").filter("setsar", "1")
        top, _, left, _ = info.bars
        stream = stream.filter("crop", info.width, info.height, left, top)
        source = info.size
    if (h, w) != source:  # to the working size, or an anamorphic stream's pixels
        stream = stream.filter("scale", w, h, flags="area" if shrink else "bicubic")
        stream = stream.filter("setsar", "1")
    cmd = (
        stream.output("pipe:", format="rawvideo", pix_fmt=pix_fmt, fps_mode="passthrough")
        .global_args("-hide_banner", "-loglevel", "error", "-nostdin")
        .compile(cmd=ffmpeg_exe())
    )
    source = local(path, "image2" in args)
    cmd = [source if arg == STAND_IN else arg for arg in cmd]
    process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    widen_pipe(process.stdout)
    said = drain(process.stderr)
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
        err = said()
        code = process.wait()
    if code != 0:
        last = err.splitlines()[-1] if err else f"exit status {code}"
        raise VideoError(f"{path}: decoding failed: {last}")
    if "partial file" in err:
        raise VideoError(f"{path}: truncated: the file ends before its last frame")


NOPTS = -(2**63)  # FFmpeg's AV_NOPTS_VALUE: a packet that carries no timestamp
DISCARD = 0x4  # FFmpeg's AV_PKT_FLAG_DISCARD: a packet decoded but never shown


def _discarded(row: list[str]) -> bool:
    """Whether a framecrc row's packet is decoded only to decode the next ones, and never
    shown: the frames an MP4's edit list cuts off its start (a clip trimmed without
    re-encoding, ``ffmpeg -ss T -c copy`` or a phone's own trim, keeps the packets from
    the keyframe before the cut). Its flags are the row's ``F=0x..`` field."""
    flags = next((f.strip()[2:] for f in row[6:] if f.strip().startswith("F=")), "0")
    return bool(int(flags, 16) & DISCARD)


def frame_times(path: str | Path, input_args: tuple = (), *, decoded: bool = False) -> np.ndarray:
    """Presentation times (s) of every video frame, from the first, in display order.

    Read from the container's packets (no decoding), so variable frame rate is exact.
    Where the packets carry no timestamps (AVI's MPEG-4 ASP, whose packets have only a
    decoding order), or with ``decoded`` (a damaged clip: the times of the frames that
    do decode, :func:`read_frames`' frames), the frames are decoded, cheaply (no pixels
    leave FFmpeg), and their own times are taken instead. Those count from the first
    frame the packets list, where they list times: frames lost at the start leave the
    first that decodes at its own time, not at 0 (its video was written 2.7 s early,
    ahead of its audio, on a clip whose first 80 frames did not decode).
    """
    listed = _framecrc_times(path, input_args, decode=False)
    times = _framecrc_times(path, input_args, decode=True) if decoded or listed is None else listed
    if times is None:
        raise VideoError(f"{path}: its frames carry no timestamps FFmpeg can read")
    # lost frames leave a frame's time at the least; less is the decoded clock's rounding
    lost = listed is not None and times[0] - listed[0] > 0.5 * frame_interval(listed)
    return times - (listed[0] if lost else times[0])


def frame_interval(times: np.ndarray) -> float:
    """The median interval between frame ``times``, s (1/30 for a single frame)."""
    return float(np.median(np.diff(times))) if len(times) > 1 else 1 / 30


def _framecrc_times(path: str | Path, input_args: tuple, *, decode: bool) -> np.ndarray | None:
    """Sorted frame times from FFmpeg's framecrc of the first video stream: its packets
    (``decode`` False) or its decoded frames; None where some carry no timestamp."""
    # (decoded frames on the encoder's clock, 1/frame rate, whose slots keep their times
    # rising: on the container's own, a stream whose packets repeat a time, as FFmpeg
    # writes a variable rate with B-frames into Matroska, gave two frames one time)
    codec = ["-c:v", "wrapped_avframe"] if decode else ["-c", "copy"]
    cmd = [ffmpeg_exe(), "-hide_banner", "-nostdin", *input_args, "-i"]
    cmd += [local(path, "image2" in input_args), "-map", "0:v:0", *codec, "-f", "framecrc", "-"]
    result = subprocess.run(cmd, capture_output=True, text=True, errors="replace")
    tb = re.search(r"#tb 0: (\d+)/(\d+)", result.stdout)
    if "partial file" in result.stderr:
        raise VideoError(f"{path}: truncated: the file ends before its last frame")
    if result.returncode != 0 or tb is None:
        raise VideoError(f"{path}: cannot read frame timestamps")
    scale = int(tb.group(1)) / int(tb.group(2))
    rows = [line.split(",") for line in result.stdout.splitlines() if line.startswith("0,")]
    pts = [int(row[2]) for row in rows if not _discarded(row)]
    if not pts:
        raise VideoError(f"{path}: no video frames")
    if NOPTS in pts or len(set(pts)) < len(pts):
        return None
    return np.sort(np.array(pts, dtype=np.float64)) * scale
