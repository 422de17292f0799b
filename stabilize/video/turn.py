"""Quarter turns of decoded frames. A clip with a display rotation (a phone held
upright or upside down) is stabilised as its sensor stored it, where its rows are the
sensor's rows in readout order (:meth:`stabilize.video.VideoInfo.stored`), and turned to
be shown only once warped; mirrored first where its display matrix also flips it (a
front camera's clip, as some apps write it)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.video import i420
from stabilize.video.binary import ffmpeg_exe, local

# OpenCV turns a 1080p I420 frame in 2.3 ms, np.rot90 and a copy in 3.5.
_CODES = {1: cv2.ROTATE_90_COUNTERCLOCKWISE, 2: cv2.ROTATE_180, 3: cv2.ROTATE_90_CLOCKWISE}


def turn(frame: NDArray, turns: int, planar: bool = False, mirror: bool = False) -> NDArray:
    """``frame`` turned ``turns`` quarter turns counter-clockwise, as ``np.rot90``, after
    it is mirrored left to right where ``mirror``: RGB (H, W, 3), or with ``planar`` I420
    (3H/2, W), plane by plane (8 or 10 bits)."""
    turns %= 4
    if turns == 0 and not mirror:
        return frame

    def shown(plane: NDArray) -> NDArray:
        plane = cv2.flip(plane, 1) if mirror else np.ascontiguousarray(plane)
        return cv2.rotate(plane, _CODES[turns]) if turns else plane

    return i420.join(*(shown(p) for p in i420.split(frame))) if planar else shown(frame)


# Seconds into the clip where the frame is read again, where the first cannot tell the
# turn from the mirror (one colour: a fade in from black)
LATER_S = (1.0, 3.0)


def display_transform(
    path: str | Path, size: tuple[int, int], input_args: tuple = ()
) -> tuple[int, bool] | None:
    """(quarter turns, mirror) that take a frame as stored, (H, W) ``size``, to the frame
    FFmpeg shows (:func:`turn`'s arguments), found by decoding the first frame both ways,
    or one :data:`LATER_S` in where it cannot tell (one colour, or symmetric); None where
    none can, or none decodes.

    FFmpeg's listing gives a display matrix's rotation only, and a flip in it changes
    that: a mirror alone reads "rotation of -180 degrees", a vertical flip "-0.00". A
    clip so flagged (a front camera's, as some apps write it) came out upside down, or
    mirrored.
    """
    for at in (None, *LATER_S):
        stored, shown = (_luma(path, input_args, auto, at) for auto in (False, True))
        if stored.size != size[0] * size[1] or shown.size != stored.size:
            return None  # past the end, or no frame decodes
        stored = stored.reshape(size).astype(np.int16)
        fits = [
            (turns, mirror)
            for mirror in (False, True)
            for turns in range(4)
            if _same(np.rot90(stored[:, ::-1] if mirror else stored, turns), shown)
        ]
        if len(fits) == 1:
            return fits[0]
    return None


def _same(candidate: NDArray, shown: NDArray) -> bool:
    """Whether ``shown`` (flat) is ``candidate``: the turn and flip move pixels whole, so
    the right one matches to the level."""
    return bool(np.abs(candidate - shown.reshape(candidate.shape)).mean() < 0.5)


def _luma(path: str | Path, input_args: tuple, autorotate: bool, at: float | None) -> NDArray:
    """A frame's luma, flat uint8 (empty where none decodes), turned by FFmpeg or as
    stored: the first, or the one ``at`` s in."""
    cmd = [ffmpeg_exe(), "-v", "error", "-nostdin", *input_args]
    cmd += ["-ss", f"{at:g}"] if at is not None else []
    cmd += [] if autorotate else ["-noautorotate"]
    cmd += ["-i", local(path, "image2" in input_args), "-map", "0:v:0", "-frames:v", "1"]
    cmd += ["-f", "rawvideo", "-pix_fmt", "gray", "-"]
    return np.frombuffer(subprocess.run(cmd, capture_output=True).stdout, np.uint8)
