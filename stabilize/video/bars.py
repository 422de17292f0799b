"""Black bars baked into a picture: a letterbox above and below, a pillarbox left and
right, as a clip shot upright and shown in a wide frame, or a wide film in a TV's frame,
stores them.

The bars belong to the frame, not to the scene. Warped with the picture, they slide into
view at its edges and shake there, where the input held them still; and the default
field of view, meant for the camera's frame, spans the bars too. On phone-cc9's 800×600
frames pillarboxed into 1068×600, the 69° default read f 777 px where the picture's own
is 582 (true 573.85). So the picture inside the bars is worked on alone, and the bars
are put back still around it (:meth:`stabilize.video.VideoInfo.within_bars`).

They are found by FFmpeg's ``cropdetect`` over the whole clip: the rows and columns that
stay black (within 8 of 255 of the range's black) in every frame it reads: its
keyframes (a few ms each), or where a clip has fewer than three, every third frame of its
first 1.5 s. Only bars a letterbox or pillarbox makes are taken: each at least 2% of its
side, the two of a pair within 1% of each other, the picture at least a quarter of each
side (a 9:16 picture pillarboxed into a 16:9 frame spans 0.32 of its width).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from stabilize.video import i420
from stabilize.video.binary import filter_log
from stabilize.video.probe import VideoInfo

# cropdetect's limit, of 255: brighter than the range's black (16 limited, 0 full) by
# more than a compression's noise is picture (limited: 24, cropdetect's own default)
ABOVE_BLACK = 8
MIN_BAR = 0.02  # of its side: a thinner black edge is the picture's, or an encoder's
PAIR = 0.01  # of its side: how far a letterbox's or pillarbox's two bars may differ
MIN_PICTURE = 0.25  # of each side: a 9:16 picture in a 16:9 frame spans 0.32 of it
SAMPLES = 3  # frames read at the least
BARS_MODES = ("auto", "off")  # --bars: the picture inside them stabilised alone, or not

# the extents of what is not black, over every frame read so far (reset=0)
_EXTENT = re.compile(r"Parsed_cropdetect.*? x1:(\d+) x2:(\d+) y1:(\d+) y2:(\d+)")


def detect_bars(info: VideoInfo) -> tuple[int, int, int, int] | None:
    """(top, bottom, left, right) in px, even, of the black bars around the picture of
    ``info``'s frames as :func:`stabilize.video.read_frames` delivers them (turned or
    stored, in square pixels), or None where there are none."""
    h, w = info.size
    options = [*info.input_args, *(() if info.autorotate else ("-noautorotate",))]
    chain = [f"scale={w}:{h},setsar=1"] if info.coded else []
    black = (0 if info.colour.full_range else 16) + ABOVE_BLACK
    chain.append(f"cropdetect=limit={black / 255:.4f}:reset=0:skip=0")
    crops = _cropdetect(info.path, options, ["-skip_frame", "nokey"], chain)
    if len(crops) < SAMPLES:  # a clip encoded with few keyframes: its first seconds
        every_third = ["select='not(mod(n\\,3))'", *chain]
        reading = ["-t", "1.5", "-skip_loop_filter", "all"]
        crops = _cropdetect(info.path, options, reading, every_third) or crops
    if not crops:
        return None
    x1, x2, y1, y2 = crops[-1]  # the extent over every frame read
    return _letterbox((y1, h - 1 - y2, x1, w - 1 - x2), (h, w))


def _cropdetect(
    path: str | Path, options: list[str], reading: list[str], chain: list[str]
) -> list[tuple[int, int, int, int]]:
    """cropdetect's running extents, frame by frame, as (x1, x2, y1, y2)."""
    log = filter_log(path, ",".join(chain), (*reading, *options))
    return [tuple(map(int, m.groups())) for m in _EXTENT.finditer(log)]


def _letterbox(
    bars: tuple[int, int, int, int], size: tuple[int, int]
) -> tuple[int, int, int, int] | None:
    """The bars, each rounded up to even, where they make a letterbox or a pillarbox (or
    both); else None.

    >>> _letterbox((0, 0, 134, 134), (600, 1068))
    (0, 0, 134, 134)
    >>> _letterbox((0, 0, 134, 0), (600, 1068)) is None  # one dark side: picture
    True
    """
    top, bottom, left, right = bars
    h, w = size
    pairs = ((top, bottom, h), (left, right, w))
    if not any(a or b for a, b, _ in pairs):
        return None
    for a, b, side in pairs:
        if (a or b) and (min(a, b) < MIN_BAR * side or abs(a - b) > PAIR * side):
            return None
        if side - a - b < MIN_PICTURE * side:
            return None
    return tuple(v + v % 2 for v in bars)


def put_back(
    frame: NDArray, bars: tuple[int, int, int, int], planar: bool, full_range: bool = False
) -> NDArray:
    """The picture ``frame`` (RGB (h, w, 3), or I420 (3h/2, w) when ``planar``) framed by
    its black ``bars`` again (top, bottom, left, right: px, even), in the range's black.

    >>> put_back(np.full((2, 2, 3), 9, np.uint8), (0, 0, 2, 2), planar=False)[0, :, 0]
    array([0, 0, 9, 9, 0, 0], dtype=uint8)
    """
    top, bottom, left, right = bars
    if not planar:
        return np.pad(frame, ((top, bottom), (left, right), (0, 0)))
    planes = i420.split(frame)
    fills = i420.black(frame, full_range)
    framed = [
        np.pad(p, ((top // s, bottom // s), (left // s, right // s)), constant_values=fill)
        for p, fill, s in zip(planes, fills, (1, 2, 2), strict=True)
    ]
    return i420.join(*framed)
