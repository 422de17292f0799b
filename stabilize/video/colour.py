"""A video's colour description, kept from the source: range, matrix, primaries, transfer.

FFmpeg lists it after the pixel format, e.g. ``yuvj420p(tv, bt709, progressive)`` or
``yuv420p10le(tv, bt2020nc/bt2020/smpte2084)``: the range (``tv``: limited, ``pc``:
full), then one name where the matrix, primaries and transfer agree, or all three as
matrix/primaries/transfer. A ``yuvj`` format is full range whatever its tag says, since
FFmpeg decodes it so (the GoPro clips read ``yuvj420p(tv, bt709)`` and their luma spans
0–255).

Pass 2 carries YUV samples through the pipe untouched, so the encoder must be told the
source's description on both sides of the pipe. Told it only on the output side, FFmpeg
converts the samples to it (a full-range luma ramp 0, 64, 129, 194 came back 0, 55, 131,
207). Told nothing, it tagged a full-range source's output as limited, and every player
then stretched its contrast: hero7's output clipped 7.7% of its pixels to white and 3.7%
to black, where the source clips 4.6% and 0.25%.

An HDR10 stream also carries its mastering display (the primaries, white point and
luminance range it was graded on) and its content light levels (MaxCLL, MaxFALL), which
a player's tone mapping reads. They travel in the frames (SEI messages), so they are read
from the first decoded frame and written again by x264 or x265
(:meth:`Colour.hdr10_args`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

# The names FFmpeg prints that its -colorspace, -color_primaries and -color_trc options
# also accept; anything else ("unknown", "reserved") is left for the encoder to default.
MATRICES = frozenset(
    "rgb bt709 fcc bt470bg smpte170m smpte240m ycgco bt2020nc bt2020c smpte2085 "
    "chroma-derived-nc chroma-derived-c ictcp".split()
)
PRIMARIES = frozenset(
    "bt709 bt470m bt470bg smpte170m smpte240m film bt2020 smpte428 smpte431 smpte432 "
    "jedec-p22 ebu3213".split()
)
TRANSFERS = frozenset(
    "bt709 gamma22 gamma28 smpte170m smpte240m linear log100 log316 iec61966-2-4 bt1361e "
    "iec61966-2-1 bt2020-10 bt2020-12 smpte2084 smpte428 arib-std-b67".split()
)
NAMES = MATRICES | PRIMARIES | TRANSFERS


@dataclass(frozen=True)
class Colour:
    """How a video's samples are to be read; None where the source does not say."""

    range: str | None = None  # "tv" (limited, 16–235) or "pc" (full, 0–255)
    matrix: str | None = None  # YUV ↔ RGB, e.g. "bt709"
    primaries: str | None = None
    transfer: str | None = None  # e.g. "smpte2084" (HDR10's PQ)
    # HDR10's static metadata, in x265's and x264's syntax: the mastering display
    # "G(x,y)B(x,y)R(x,y)WP(x,y)L(max,min)" (chromaticities in 1/50000, luminance in
    # 1/10000 cd/m²), and the content light levels "MaxCLL,MaxFALL" (cd/m²)
    mastering: str | None = None
    light: str | None = None
    # Dolby Vision, as "profile.compatibility" (an iPhone's HDR clip: "8.4", HLG inside);
    # its per-frame metadata does not travel through the pipe, so only its base layer
    # (:data:`DOLBY_BASE`) is kept
    dolby_vision: str | None = None
    # HDR10+ (SMPTE 2094-40: a Samsung phone's HDR video), whose per-frame tone mapping
    # does not travel through the pipe either: its HDR10 base and static metadata are kept
    hdr10_plus: bool = False

    @property
    def full_range(self) -> bool:
        return self.range == "pc"

    def ffmpeg_args(self) -> list[str]:
        """FFmpeg's options that state this description (none for what is unknown).

        >>> Colour("pc", "bt709", "bt709", "bt709").ffmpeg_args()[:4]
        ['-color_range', 'pc', '-colorspace', 'bt709']
        >>> Colour().ffmpeg_args()
        []
        """
        pairs = (
            ("-color_range", self.range),
            ("-colorspace", self.matrix),
            ("-color_primaries", self.primaries),
            ("-color_trc", self.transfer),
        )
        return [arg for flag, value in pairs if value for arg in (flag, value)]

    def hdr10_args(self, codec: str) -> list[str]:
        """The encoder's options that write the HDR10 metadata again (x264 and x265 take
        it; none where there is none, or for another encoder: :attr:`hdr10_lost`).

        >>> Colour(mastering="G(1,2)B(3,4)R(5,6)WP(7,8)L(9,1)", light="10,5").hdr10_args("libx265")
        ['-x265-params', 'hdr10=1:master-display=G(1,2)B(3,4)R(5,6)WP(7,8)L(9,1):max-cll=10,5']
        """
        if codec == "libx265":
            parts = ["hdr10=1"]
            parts += [f"master-display={self.mastering}"] if self.mastering else []
            parts += [f"max-cll={self.light}"] if self.light else []
            return ["-x265-params", ":".join(parts)] if len(parts) > 1 else []
        if codec == "libx264":
            parts = [f"mastering-display={self.mastering}"] if self.mastering else []
            parts += [f"cll={self.light}"] if self.light else []
            return ["-x264-params", ":".join(parts)] if parts else []
        return []

    def hdr10_lost(self, codec: str) -> bool:
        """Whether ``codec`` would drop the HDR10 metadata this description carries."""
        return bool(self.mastering or self.light) and not self.hdr10_args(codec)


UNKNOWN = Colour()  # a source that says nothing: the encoder's defaults

# What a player shows of a Dolby Vision stream without its metadata, by the base layer's
# signal compatibility id; 0 (profile 5) is Dolby's own IPT colour space, which no player
# shows right without it
DOLBY_BASE = {"1": "HDR10", "2": "SDR (BT.709)", "4": "HLG", "6": "HDR10"}
_DOVI = re.compile(r"DOVI configuration record: .*?profile: (\d+).*?compatibility id: (\d+)")


def dolby_vision(listing: str) -> str | None:
    """The Dolby Vision profile FFmpeg lists for a stream, as "profile.compatibility";
    None where it lists none.

    >>> dolby_vision("      DOVI configuration record: version: 1.0, profile: 8, level: 4, "
    ...              "rpu flag: 1, el flag: 0, bl flag: 1, compatibility id: 4")
    '8.4'
    >>> dolby_vision("  Stream #0:0: Video: hevc (Main 10), yuv420p10le") is None
    True
    """
    m = _DOVI.search(listing)
    return f"{m.group(1)}.{m.group(2)}" if m else None


_MASTERING = re.compile(
    r"Mastering display metadata: has_primaries:1 has_luminance:1 "
    r"r\(([\d.]+)[, ]+([\d.]+)\) g\(([\d.]+)[, ]+([\d.]+)\) b\(([\d.]+)[, ]+([\d.]+)\) "
    r"wp\(([\d.]+)[, ]+([\d.]+)\) min_luminance=([\d.]+), max_luminance=([\d.]+)"
)
_LIGHT = re.compile(r"Content light level metadata: MaxCLL=(\d+), MaxFALL=(\d+)")


def with_hdr10(colour: Colour, report: str) -> Colour:
    """``colour`` with the HDR10 metadata a first frame's ``showinfo`` report gives
    (:func:`stabilize.video.first_frame.first_frame_report`), if any, and whether it
    carries HDR10+'s.

    >>> line = ("Mastering display metadata: has_primaries:1 has_luminance:1 "
    ...         "r(0.6800,0.3200) g(0.2650,0.6900) b(0.1500 0.0600) wp(0.3127, 0.3290) "
    ...         "min_luminance=0.005000, max_luminance=1000.000000")
    >>> with_hdr10(Colour(), line).mastering
    'G(13250,34500)B(7500,3000)R(34000,16000)WP(15635,16450)L(10000000,50)'
    """
    m, light = _MASTERING.search(report), _LIGHT.search(report)
    mastering = None
    if m:
        rx, ry, gx, gy, bx, by, wx, wy = (round(float(v) * 50000) for v in m.groups()[:8])
        low, high = (round(float(v) * 10000) for v in m.groups()[8:])
        mastering = f"G({gx},{gy})B({bx},{by})R({rx},{ry})WP({wx},{wy})L({high},{low})"
    cll = f"{light.group(1)},{light.group(2)}" if light else None
    plus = "SMPTE2094-40" in report
    return replace(colour, mastering=mastering, light=cll, hdr10_plus=plus)


def colour_of(pix_fmt: str, details: str) -> Colour:
    """The colour description FFmpeg lists for a stream of ``pix_fmt``, from the
    ``details`` it prints in parentheses after it.

    >>> colour_of("yuvj420p", "tv, bt709, progressive").ffmpeg_args()[1::2]
    ['pc', 'bt709', 'bt709', 'bt709']
    >>> colour_of("yuv420p10le", "tv, bt2020nc/bt2020/smpte2084").ffmpeg_args()[1::2]
    ['tv', 'bt2020nc', 'bt2020', 'smpte2084']
    >>> colour_of("yuv420p", "progressive") == Colour()
    True
    """
    tokens = [t.strip() for t in details.split(",")]
    ranges = [t for t in tokens if t in ("tv", "pc")]
    rng = "pc" if pix_fmt.startswith("yuvj") else (ranges[0] if ranges else None)
    named = [t for t in tokens if "/" in t or t in NAMES]
    if not named:
        return Colour(rng)
    parts = named[0].split("/")
    matrix, primaries, transfer = parts if len(parts) == 3 else (parts[0],) * 3
    return Colour(
        rng,
        matrix if matrix in MATRICES else None,
        primaries if primaries in PRIMARIES else None,
        transfer if transfer in TRANSFERS else None,
    )
