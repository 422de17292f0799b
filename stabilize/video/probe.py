"""What a video is: size, rate, rotation, codec, streams.

Probing parses what ``ffmpeg -i`` reports, since the bundled FFmpeg of imageio-ffmpeg
comes without ffprobe.
"""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass, replace
from fractions import Fraction
from pathlib import Path

from stabilize.video.binary import ffmpeg_exe, local
from stabilize.video.colour import UNKNOWN, Colour, colour_of, dolby_vision, with_hdr10
from stabilize.video.fields import DEINTERLACE_MODES, field_order, frame_field_order, interlaced
from stabilize.video.first_frame import first_frame_report
from stabilize.video.i420 import has_alpha, is_deep
from stabilize.video.sequence import (
    exif_orientation,
    first_image,
    gap_message,
    is_pattern,
    sequence_args,
)
from stabilize.video.turn import display_transform


class VideoError(ValueError):
    """The input is missing, not a video, or unreadable; the message is one line."""


@dataclass(frozen=True)
class Stream:
    """One stream of the input as FFmpeg lists it: its index, kind, codec and language."""

    index: int
    kind: str  # "video", "audio", "subtitle", "data" or "attachment"
    codec: str
    language: str = ""
    start: float | None = None  # s, where FFmpeg lists one apart from the file's
    tag: str = ""  # the container's codec tag, e.g. 'avc1', 'text'
    title: str = ""  # its title ('name' in MP4, which FFmpeg writes back under another key)
    timecode: str = ""  # SMPTE start timecode (HH:MM:SS:FF), where the stream carries one
    cover: bool = False  # a cover picture (FFmpeg's "attached pic"): one still, not a video
    filename: str = ""  # an attached file's name (a font's, in Matroska)
    channels: int = 0  # an audio track's channels (0: not audio, or not listed)


@dataclass(frozen=True)
class VideoInfo:
    """What FFmpeg reports of a video: its first video stream, and every stream it has."""

    path: Path | str
    # as decoded: as shown, after the display rotation (unless ``autorotate`` is off), in
    # square pixels (an anamorphic stream's frames are resampled to them: ``coded``)
    width: int
    height: int
    fps: float
    duration: float | None
    rotation: int  # display rotation in degrees, counter-clockwise
    has_audio: bool
    codec: str
    pix_fmt: str
    input_args: tuple = ()  # FFmpeg input options, e.g. an image sequence's start number
    streams: tuple[Stream, ...] = ()
    start: float = 0.0  # the container's start time, s: its earliest stream's first timestamp
    chapters: int = 0
    metadata: str = ""  # the file's own tags as FFmpeg lists them (before its streams)
    colour: Colour = UNKNOWN  # range, matrix, primaries, transfer: kept in the output
    autorotate: bool = True  # whether FFmpeg turns the frames by the display rotation
    field_order: str = ""  # "progressive", "tff", "bff", or "" where FFmpeg names none
    deinterlace: bool = False  # whether frames are deinterlaced on decoding (bwdif)
    fields: bool = False  # whether each field is decoded as a frame (twice the frames, at fps)
    # An anamorphic stream's sample aspect ratio (its pixels' width over their height, as
    # "4:3"), and (H, W) of its frames as FFmpeg decodes them, before they are resampled
    # to square pixels; None where the pixels are square
    pixel_aspect: str = "1:1"
    coded: tuple[int, int] | None = None
    # Black bars baked into the frame (:mod:`stabilize.video.bars`): (top, bottom, left,
    # right) px, and the whole frame's (H, W); the frames are then the picture inside
    # them (``size``), and the bars are put back around it on writing
    bars: tuple[int, int, int, int] | None = None
    framed: tuple[int, int] | None = None
    # closed captions (EIA-608/708, a broadcast's) carried in the video's own frames,
    # which FFmpeg's listing names on the stream's line
    captions: bool = False
    # whether the frames carry an alpha (transparency) plane the pipe leaves out: its
    # pixel format has one, and, for a GIF (which FFmpeg decodes as bgra whatever it
    # holds), some frame of it declares a transparent colour
    alpha: bool = False
    # whether the shown frames are the stored ones mirrored left to right, before the
    # display rotation turns them: a display matrix with a flip (a front camera's)
    mirror: bool = False

    @property
    def size(self) -> tuple[int, int]:
        return (self.height, self.width)

    @property
    def turns(self) -> int:
        """Quarter turns, counter-clockwise, from the decoded frames to the shown ones
        (as ``np.rot90``): 0 unless the display rotation is left to the caller."""
        return 0 if self.autorotate else self.rotation // 90

    @property
    def mirrored(self) -> bool:
        """Whether the decoded frames are mirrored left to right (before :attr:`turns`)
        to be shown: False unless the display rotation is left to the caller."""
        return self.mirror and not self.autorotate

    @property
    def shown_size(self) -> tuple[int, int]:
        """(H, W) of the frames as a player shows them."""
        return self.size[::-1] if self.turns % 2 else self.size

    def stored(self) -> VideoInfo:
        """The video as its sensor stored it: decoded without the display rotation
        (FFmpeg's ``-noautorotate``) where it is a whole number of quarter turns. Its
        rows are then the sensor's rows, read out one after another under a rolling
        shutter, however the camera was held; :attr:`turns` turns them to be shown."""
        if not self.autorotate or (self.rotation not in (90, 180, 270) and not self.mirror):
            return self
        h, w = self.size[::-1] if self.rotation in (90, 270) else self.size
        coded = self.coded and (self.coded[::-1] if self.rotation in (90, 270) else self.coded)
        return replace(self, width=w, height=h, autorotate=False, coded=coded)

    @property
    def decoded_size(self) -> tuple[int, int]:
        """(H, W) of the frames as FFmpeg decodes them, before any resampling."""
        return self.coded or self.framed_size

    @property
    def framed_size(self) -> tuple[int, int]:
        """(H, W) of the whole frame, its bars included (``size`` without bars)."""
        return self.framed or self.size

    @property
    def shown_framed_size(self) -> tuple[int, int]:
        """(H, W) of the whole frame as a player shows it, its bars included."""
        return self.framed_size[::-1] if self.turns % 2 else self.framed_size

    def within_bars(self, bars: tuple[int, int, int, int] | None) -> VideoInfo:
        """The video decoded as the picture inside ``bars`` (top, bottom, left, right:
        px of its frames as decoded, even), which writing puts back around it. Last of
        :meth:`stored` and :meth:`deinterlaced`: the bars are the decoded frames'."""
        if not bars:
            return self
        top, bottom, left, right = bars
        h, w = self.size
        return replace(
            self, width=w - left - right, height=h - top - bottom, bars=bars, framed=(h, w)
        )

    @property
    def video_delay(self) -> float:
        """How late the first video stream starts after the file's first stream, s (a TS
        recording's video often starts some ms after its audio)."""
        video = next((s for s in self.streams if s.kind == "video"), None)
        if video is None or video.start is None:
            return 0.0
        return max(video.start - self.start, 0.0)

    def deinterlaced(self, mode: str = "auto") -> VideoInfo:
        """The video as it will be decoded under ``--deinterlace`` ``mode``
        (:mod:`stabilize.video.fields`): ``auto`` deinterlaces a stream whose field order
        says it is interlaced (what :func:`probe` sets), ``on`` every stream (one flagged
        progressive but combed), ``off`` none, ``fields`` every stream, each field into a
        frame of its own (twice the frames, at twice the rate)."""
        if mode not in DEINTERLACE_MODES:
            raise ValueError(f"--deinterlace must be one of {', '.join(DEINTERLACE_MODES)}")
        if mode == "fields":  # at twice the frame rate
            return replace(self, deinterlace=True, fields=True, fps=2 * self.fps)
        every = {"auto": interlaced(self.field_order), "on": True, "off": False}[mode]
        return replace(self, deinterlace=every)

    def of_kind(self, kind: str) -> tuple[Stream, ...]:
        """The streams of one kind ("audio", "subtitle", ...), in the file's order."""
        return tuple(s for s in self.streams if s.kind == kind)


# the pixel format's details may hold parentheses of their own: "(tv, top coded first
# (swapped))"
_VIDEO = re.compile(
    r"Stream #\S+.*?: Video: (\w+).*?, (\w+)(?:\(((?:[^()]|\([^()]*\))*)\))?, "
    r".*?(\d{2,5})x(\d{2,5})"
)
_FPS = re.compile(r"(\d+(?:\.\d+)?) (?:fps|tbr)")
_DURATION = re.compile(r"Duration: (\d+):(\d+):(\d+(?:\.\d+)?)")
_START = re.compile(r"Duration: [^\n]*?start: (-?\d+(?:\.\d+)?)")
_STREAM = re.compile(
    r"Stream #0:(\d+)(?:\[\w+\])?(?:\((\w+)\))?: (Video|Audio|Subtitle|Data|Attachment): (\w+)"
)
# A URL's scheme, its "//" read as one "/" once it has been a Path
_URL = re.compile(r"([A-Za-z][A-Za-z0-9+.-]+):/+")
_SAR = re.compile(r"\[SAR (\d+):(\d+) DAR")
_ROTATION = re.compile(r"rotation of (-?\d+(?:\.\d+)?) degrees|rotate\s*:\s*(-?\d+)")


def exact_rate(listed: float) -> float:
    """The frame rate FFmpeg lists to two decimals, NTSC's N·1000/1001 made whole.

    A clip at 24000/1001 fps is listed as "23.98": written at 23.98 fps, its video ran
    ahead of its audio by 0.1 s every 10 minutes, and MXF refused the rate. A listed rate
    that N·1000/1001 rounds to, and no whole N, is taken to be that rate.

    >>> exact_rate(23.98) == 24000 / 1001, exact_rate(29.97) == 30000 / 1001
    (True, True)
    >>> exact_rate(25.0), exact_rate(29.74)
    (25.0, 29.74)
    """
    whole = round(listed * 1.001)
    ntsc = whole * 1000 / 1001
    return ntsc if whole and listed != whole and round(ntsc, 2) == listed else listed


def _listing(text: str, start: int) -> str:
    """What FFmpeg lists of the stream whose line starts at ``start``: its line, its
    Metadata and Side data lines, up to the next stream (indented deeper within a stream
    group)."""
    return re.split(r"\n\s*Stream #", text[start:], maxsplit=1)[0]


def _stream(match: re.Match, text: str) -> Stream:
    line = text[match.start() : text.find("\n", match.start())]
    block = _listing(text, match.start())
    title = re.search(r"^\s+(?:title|name)\s*: (.*)$", block, re.M)
    start = re.search(r", start (-?\d+(?:\.\d+)?)", line)
    tag = re.search(r"\((\w+) / 0x[0-9A-Fa-f]+\)", line)
    timecode = re.search(r"^\s+timecode\s*: (\S+)", block, re.M | re.I)  # MKV: TIMECODE
    filename = re.search(r"^\s+filename\s*: (.*)$", block, re.M | re.I)
    layout = re.search(r" Hz, ([^,]+),", line)
    return Stream(
        int(match.group(1)),
        match.group(3).lower(),
        match.group(4),
        match.group(2) or "",
        float(start.group(1)) if start else None,
        tag.group(1) if tag else "",
        title.group(1).strip() if title else "",
        timecode.group(1) if timecode else "",
        "(attached pic)" in line,
        filename.group(1).strip() if filename else "",
        channel_count(layout.group(1)) if layout else 0,
    )


# FFmpeg's names of channel layouts that give no count in figures
NAMED_LAYOUTS = {"mono": 1, "stereo": 2, "downmix": 2, "binaural": 2, "quad": 4,
                 "hexagonal": 6, "octagonal": 8, "cube": 8, "hexadecagonal": 16}  # fmt: skip


def channel_count(layout: str) -> int:
    """The channels of an audio layout as FFmpeg lists it (0: a name it does not know).

    >>> [channel_count(n) for n in ("stereo", "5.1(side)", "7.1", "quad(side)", "3 channels")]
    [2, 6, 8, 4, 3]
    """
    layout = layout.strip()
    if figures := re.fullmatch(r"(\d+)\.(\d+)(?:\(.*\))?", layout):
        return int(figures.group(1)) + int(figures.group(2))
    if counted := re.fullmatch(r"(\d+) channels(?: \(.*\))?", layout):
        return int(counted.group(1))
    return NAMED_LAYOUTS.get(layout.split("(")[0], 0)


def _from_frames(path: Path, input_args: tuple, pix_fmt: str, details: str) -> tuple[str, Colour]:
    """The field order and the colour description, from the stream's header, and from
    its first decoded frame where the header leaves them open: the field order where it
    names none (:mod:`stabilize.video.fields`), the HDR10 metadata of a stream of 10
    bits or more (:mod:`stabilize.video.colour`)."""
    order, colour = field_order(details), colour_of(pix_fmt, details)
    deep = is_deep(pix_fmt)
    if order and not deep:
        return order, colour
    report = first_frame_report(path, input_args)
    return order or frame_field_order(report), with_hdr10(colour, report)


def probe(path: str | Path, input_args: tuple = ()) -> VideoInfo:
    """What FFmpeg reports of the first video stream, or :class:`VideoError`.

    ``path`` may be an image-sequence pattern (``frames/img-%d.jpg``) with the input
    options of :func:`sequence_args` (by default its lowest number, at 30 fps).
    """
    pattern = is_pattern(path)
    input_args = input_args or sequence_args(path)  # a sequence's first number, at 30 fps
    path = Path(path)
    if str(path) == "-" and not path.exists():  # it read "-: no such file"
        raise VideoError(
            "IN '-': a clip is read in two passes, not from standard input: save it first"
        )
    if not pattern and not path.exists() and (url := _URL.match(str(path))):
        # FFmpeg would stream it, but a clip is read three times (probe, two passes):
        # downloaded three times, and a live stream's passes would see different frames
        raise VideoError(
            f"{url.group(1)}://{str(path)[url.end() :]}: a URL: download the clip first"
        )
    if not pattern and not path.exists():
        raise VideoError(f"{path}: no such file")
    if pattern and (first := first_image(input_args)) is None:
        raise VideoError(f"{path}: no file matches this pattern")
    if pattern and (gap := gap_message(path, first)):
        raise VideoError(gap)
    if path.is_dir():
        raise VideoError(f"{path}: is a folder, not a video (give a pattern like dir/img-%d.jpg)")
    if not pattern and not path.is_file():
        # a pipe (<(curl ...), a FIFO) is read once, where a clip is read in two passes:
        # a FIFO with no writer waited for ever, a process substitution read "not a video"
        raise VideoError(f"{path}: is a pipe or a device, not a file: save the clip first")
    result = subprocess.run(
        [ffmpeg_exe(), "-hide_banner", "-nostdin", *input_args, "-i", local(path, pattern)],
        capture_output=True,
        text=True,
        errors="replace",
    )
    text = result.stderr
    video = _VIDEO.search(text)
    if video is None and re.search(r"Stream #\S+.*?: Audio: ", text):
        raise VideoError(f"{path}: has no video stream, only audio")
    if video is None:
        raise VideoError(f"{path}: not a video FFmpeg can read")
    codec, pix_fmt, w, h = video.group(1), video.group(2), int(video.group(4)), int(video.group(5))
    stream_line = text[video.start() : text.find("\n", video.start())]
    fps_match = _FPS.search(stream_line)
    fps = exact_rate(float(fps_match.group(1))) if fps_match else 0.0
    given = dict(zip(input_args[::2], input_args[1::2], strict=False)).get("-framerate")
    fps = float(given) if given else fps  # an image sequence's --fps, as the user gave it
    dur = _DURATION.search(text)
    duration = (
        int(dur.group(1)) * 3600 + int(dur.group(2)) * 60 + float(dur.group(3)) if dur else None
    )
    rot = _ROTATION.search(text)
    rotation = int(round(float(rot.group(1) or rot.group(2)))) % 360 if rot else 0
    mirror = False
    if pattern and not rot:  # an image's EXIF orientation, which FFmpeg does not list
        rotation, mirror = exif_orientation(path, first)
    elif rot and (shown := display_transform(path, (h, w), input_args)):
        # the listed rotation is not the turn where the matrix also flips the frame
        rotation, mirror = 90 * shown[0], shown[1]
    sar = _SAR.search(stream_line)
    aspect = Fraction(int(sar.group(1)), int(sar.group(2))) if sar and int(sar.group(2)) else 0
    aspect = aspect or Fraction(1)  # none, or 0:1 ("unknown"): square
    coded = None
    if aspect != 1:  # widened to square pixels, to the even size nearest its display
        coded = (h, w)
        w = 2 * round(w * aspect / 2)
    if rotation in (90, 270):
        w, h = h, w
        coded = coded and coded[::-1]
    order, colour = _from_frames(path, input_args, pix_fmt, video.group(3) or "")
    colour = replace(colour, dolby_vision=dolby_vision(_listing(text, video.start())))
    streams = tuple(_stream(m, text) for m in _STREAM.finditer(text))
    if all(s.cover for s in streams if s.kind == "video"):  # a song's: "has 1 frame(s)"
        raise VideoError(f"{path}: has no video stream, only audio and a cover picture")
    has_audio = any(s.kind == "audio" for s in streams)
    start = _START.search(text)
    return VideoInfo(
        path,
        w,
        h,
        fps,
        duration,
        rotation,
        has_audio,
        codec,
        pix_fmt,
        tuple(input_args),
        streams,
        float(start.group(1)) if start else 0.0,
        len(re.findall(r"^\s+Chapter #", text, re.M)),
        text[: text.find("Stream #")],
        colour,
        field_order=order,
        deinterlace=interlaced(order),
        pixel_aspect=f"{aspect.numerator}:{aspect.denominator}",
        coded=coded,
        captions="Closed Captions" in stream_line,
        mirror=mirror,
        alpha=has_alpha(pix_fmt) and (codec != "gif" or _gif_transparent(path)),
    )


def _gif_transparent(path: Path) -> bool:
    """Whether some frame of a GIF declares a transparent colour (True where it cannot be
    read: the notice errs on the side of saying)."""
    try:
        from PIL import Image, ImageSequence

        with Image.open(path) as gif:
            return any("transparency" in frame.info for frame in ImageSequence.Iterator(gif))
    except (OSError, ValueError, ImportError):
        return True
