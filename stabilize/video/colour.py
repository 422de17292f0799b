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
"""

from __future__ import annotations

from dataclasses import dataclass

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


UNKNOWN = Colour()  # a source that says nothing: the encoder's defaults


def colour_of(pix_fmt: str, details: str) -> Colour:
    """The colour description FFmpeg lists for a stream of ``pix_fmt``, from the
    ``details`` it prints in parentheses after it.

    >>> colour_of("yuvj420p", "tv, bt709, progressive")
    Colour(range='pc', matrix='bt709', primaries='bt709', transfer='bt709')
    >>> colour_of("yuv420p10le", "tv, bt2020nc/bt2020/smpte2084")
    Colour(range='tv', matrix='bt2020nc', primaries='bt2020', transfer='smpte2084')
    >>> colour_of("yuv420p", "progressive")
    Colour(range=None, matrix=None, primaries=None, transfer=None)
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
