"""Image sequences: a clip stored as one picture per frame, named by a pattern whose
``%d`` (or ``%05d``) is the frame's number, as a dataset's frames are (phone-cc9's
``RE_frame-%d.jpg``).

As an input it is read from the lowest number its files carry, at a frame rate given
(:func:`sequence_args`). As an output (``frames/%05d.png``) it is written into a hidden
folder beside the target and moved into place once every frame is written
(:func:`stabilize.video.atomic.atomic_output`).
"""

from __future__ import annotations

import os
import re
from itertools import pairwise
from pathlib import Path

SEQUENCE_FPS = 30.0  # an image sequence's frame rate where none is given (a phone's)
_NUMBER = re.compile(r"%0?\d*d")  # the frame number's place in a pattern: %d, %05d


def is_pattern(path: str | Path) -> bool:
    """Whether ``path`` names an image sequence: its file name holds a frame number, and
    no file has that very name (a clip called ``50%done.mp4`` is a clip).

    >>> is_pattern("frames/img-%05d.jpg"), is_pattern("out/%d.png"), is_pattern("a%20b.mp4")
    (True, True, False)
    """
    return bool(_NUMBER.search(Path(path).name)) and not Path(path).is_file()


def _split(name: str) -> tuple[str, re.Match, str] | None:
    """A pattern's file name around its frame number: (before, the number's spec,
    after), or None where it holds none."""
    spec = _NUMBER.search(name)
    return None if spec is None else (name[: spec.start()], spec, name[spec.end() :])


def image2_path(pattern: str | Path) -> str:
    """An image-sequence pattern as FFmpeg's image2 reads it: every ``%`` but the frame
    number's doubled, since FFmpeg takes a ``%`` anywhere in the path, its folders' names
    included, for a number's place, and a folder named ``a100%b`` made every picture
    "the same name".

    >>> image2_path("/clips/100% sharp/img%-%05d.png")
    '/clips/100%% sharp/img%%-%05d.png'
    """
    folder, name = os.path.split(str(pattern))
    parts = _split(name)
    if parts is None:
        return str(pattern).replace("%", "%%")
    head, spec, tail = parts
    name = head.replace("%", "%%") + spec.group() + tail.replace("%", "%%")
    return os.path.join(folder.replace("%", "%%"), name)


def picture(pattern: str | Path, number: int) -> Path:
    """The file of image ``number`` of a pattern: only the name's frame number filled in
    (Python's ``%`` would take one in a folder's name for a format of its own).

    >>> picture("/clips/50% off/img-%05d.jpg", 99).as_posix()
    '/clips/50% off/img-00099.jpg'
    """
    path = Path(pattern)
    parts = _split(path.name)
    if parts is None:
        return path
    head, spec, tail = parts
    return path.with_name(head + _digits(spec, number) + tail)


def sequence_files(pattern: str | Path) -> dict[int, Path]:
    """The files an image-sequence pattern names that exist, by their number.

    >>> sequence_files("/no/such/folder/img-%d.jpg")
    {}
    """
    path = Path(pattern)
    parts = _split(path.name)
    if parts is None or not path.parent.is_dir():
        return {}
    head, spec, tail = parts
    name = re.compile(re.escape(head) + r"(\d+)" + re.escape(tail) + "$")
    found = ((name.match(p.name), p) for p in path.parent.iterdir())
    # only the digits FFmpeg writes for the number: a looser match took 0001.png for a
    # picture of %03d.png, which an output's --overwrite then deleted
    return {
        int(m.group(1)): p for m, p in found if m and _digits(spec, int(m.group(1))) == m.group(1)
    }


def _digits(spec: re.Match, number: int) -> str:
    """The digits FFmpeg names picture ``number`` with in a pattern's ``spec``: padded
    with zeros to its width, a space's flag or not (``%4d`` too: 0001, not C's "   1").

    >>> [_digits(_NUMBER.search(s), 7) for s in ("%d", "%03d", "%4d")]
    ['7', '007', '0007']
    """
    return str(number).zfill(int(spec.group()[1:-1] or 0))


def first_number(pattern: str | Path) -> int | None:
    """The lowest number among the files an image-sequence pattern names (``img-%05d.jpg``:
    ``img-00099.jpg`` → 99), or None where none exists. FFmpeg itself tries only 0–4, so
    a sequence cut from a longer one (phone-cc9's frames start at 99) was not found."""
    return min(sequence_files(pattern), default=None)


# EXIF's Orientation (tag 274) → (the display rotation, degrees counter-clockwise, as
# FFmpeg gives a video's; whether the stored picture is mirrored left to right before it
# turns): 6, "turn 90° clockwise to show", is a phone held upright; the mirrored ones
# (2, 4, 5, 7) are a front camera's photos saved as its preview showed them
EXIF_ORIENTATION = {
    1: (0, False), 2: (0, True), 3: (180, False), 4: (180, True),
    5: (90, True), 6: (270, False), 7: (270, True), 8: (90, False),
}  # fmt: skip


def exif_orientation(pattern: str | Path, number: int) -> tuple[int, bool]:
    """(display rotation, mirror) that image ``number``'s EXIF Orientation asks for,
    which FFmpeg's listing of an image sequence does not give: a phone's photos held
    upright are stored sideways, with orientation 6. (0, False) where it says none."""
    try:
        from PIL import Image

        with Image.open(picture(pattern, number)) as image:
            return EXIF_ORIENTATION.get(int(image.getexif().get(0x0112, 1)), (0, False))
    except (OSError, ValueError, ImportError):
        return 0, False


def gap_message(pattern: str | Path, start: int) -> str | None:
    """What is missing where an image sequence has a gap after image ``start``, or None
    where its images run on without one. FFmpeg reads a sequence only up to its first
    gap, so every image after it would be lost without a word.

    >>> gap_message("/no/such/folder/img-%d.jpg", 1) is None
    True
    """
    numbers = sorted(n for n in sequence_files(pattern) if n >= start)
    gaps = [(a, b) for a, b in pairwise(numbers) if b > a + 1]
    if not gaps:
        return None
    (before, after), lost = gaps[0], len([n for n in numbers if n > gaps[0][0]])
    one = after == before + 2
    missing = f"image {before + 1} is" if one else f"images {before + 1}–{after - 1} are"
    return (
        f"{pattern}: {missing} missing ({start}–{before} exist, then {after} on): FFmpeg reads "
        f"a sequence only up to its first gap, so the {lost} images after it would be lost; "
        "fill the gap or renumber the images"
    )


def sequence_args(
    path: str | Path, start_number: int | None = None, fps: float | None = None
) -> tuple:
    """FFmpeg input options for an image sequence, else none: its first number
    (``start_number``, else the lowest its files carry; left out where none exists) and
    its frame rate (``fps``, else :data:`SEQUENCE_FPS`)."""
    if not is_pattern(path):
        return ()
    start = first_number(path) if start_number is None else start_number
    first = () if start is None else ("-start_number", str(start))
    return ("-f", "image2", *first, "-framerate", str(fps or SEQUENCE_FPS))


def rate_notice(path: str | Path, fps: float | None) -> tuple[str, ...]:
    """A notice where an image sequence is read at :data:`SEQUENCE_FPS` for want of
    ``fps``: its pictures hold no rate, and a 60 fps burst came out at half its speed,
    unsaid."""
    if not is_pattern(path) or fps is not None:
        return ()
    return (f"an image sequence holds no frame rate: read at {SEQUENCE_FPS:g} fps (--fps sets it)",)


def first_image(input_args: tuple) -> int | None:
    """The first image's number in an image sequence's input options; None for a video
    (or a pattern that names no file)."""
    args = dict(zip(input_args[::2], input_args[1::2], strict=False))
    return int(args["-start_number"]) if "-start_number" in args else None
