"""Interlaced video: which field comes first, and FFmpeg's deinterlacer for it.

A camcorder's 50i or 60i clip stores each frame as two fields, its odd and its even rows,
captured half a frame interval apart. Warped as one picture, the fields' rows blend into
combs wherever the scene moved between them, and the output, encoded progressive, shows
them: on a rendered 50i street clip shaken 1.5°, the combing the warp left read 0.91
(the mean of |row − mean of its neighbours| over that of |row above − row below|), against
0.43 for the progressive source and 0.26 deinterlaced first. So each frame is
deinterlaced on decoding, by FFmpeg's ``bwdif`` (Bob Weaver: each missing row
interpolated in space and in time, with yadif's checks against false motion), one frame
for each frame: every frame and its time stay as they were, and the output is progressive.

``--deinterlace fields`` makes each field a frame of its own instead (50i → 50p, what a
television shows): twice the frames, each at its field's time, half a frame interval
apart, so the motion runs as smoothly as it was filmed.
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

# What ``ffmpeg -i`` prints, in the parentheses after the pixel format, for each field
# order (libavcodec's av_field_order names), and ours: tff and bff are top and bottom
# field first; "swapped" stores one order and shows the other, which bwdif reads from
# each frame's own flags.
_FFMPEG_NAMES = {
    "progressive": "progressive",
    "top first": "tff",
    "bottom first": "bff",
    "top coded first (swapped)": "tff",
    "bottom coded first (swapped)": "bff",
}
DEINTERLACE_MODES = ("auto", "on", "off", "fields")


def field_order(details: str) -> str:
    """``"tff"``, ``"bff"`` or ``"progressive"`` from the details FFmpeg lists in the
    parentheses after a stream's pixel format, or ``""`` where it names none.

    >>> field_order("pc, bt709, top first")
    'tff'
    >>> field_order("tv, bottom coded first (swapped)")
    'bff'
    >>> field_order("tv, bt709")
    ''
    """
    tokens = (t.strip() for t in details.split(","))
    return next((_FFMPEG_NAMES[t] for t in tokens if t in _FFMPEG_NAMES), "")


_FRAME_ORDER = {"P": "progressive", "T": "tff", "B": "bff"}


def frame_field_order(report: str) -> str:
    """The field order a decoded frame is flagged with, from its ``showinfo`` report
    (:func:`stabilize.video.first_frame.first_frame_report`): a DV camcorder's stream in
    AVI flags its frames interlaced, and its header says nothing. ``""`` where none.

    >>> frame_field_order("[Parsed_showinfo_0 @ 0x1] n:   0 pts: 0 fmt:yuv420p i:T iskey:1")
    'tff'
    """
    flag = re.search(r" i:([PTB]) ", report)
    return _FRAME_ORDER[flag.group(1)] if flag else ""


def interlaced(order: str) -> bool:
    """Whether a stream of this field order stores fields (FFmpeg's word for it: not
    progressive, and known)."""
    return order in ("tff", "bff")


def deinterlace_filter(every_frame: bool, fields: bool = False) -> tuple[str, dict[str, str]]:
    """FFmpeg's filter and options: ``bwdif``, a frame out for each frame in
    (``send_frame``), or for each field (``fields``: every frame, two out for each), the
    parity from each frame's flags. ``every_frame`` deinterlaces every frame, as a stream
    flagged progressive but combed needs; otherwise only the frames flagged interlaced (a
    stream may mix them)."""
    return "bwdif", {
        "mode": "send_field" if fields else "send_frame",
        "parity": "auto",
        "deint": "all" if every_frame or fields else "interlaced",
    }


def field_times(times: NDArray) -> NDArray[np.float64]:
    """The times of the fields of frames at ``times`` (s): each frame's, and half way to
    the next (the last frame's second field half the median interval after it).

    >>> field_times(np.array([0.0, 0.04, 0.08])).round(3).tolist()
    [0.0, 0.02, 0.04, 0.06, 0.08, 0.1]
    """
    times = np.asarray(times, dtype=np.float64)
    step = np.diff(times)
    last = float(np.median(step)) if len(step) else 0.04
    return np.column_stack([times, times + np.append(step, last) / 2]).ravel()
