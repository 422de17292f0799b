"""Cuts: where an edited clip changes from one shot to another.

No camera turns across a cut, yet the vote reads some rotation there: the flow between
two unrelated pictures agrees on little (a hero7 shot cut to a karma one: 1.4% of its
vectors, against 11% on either side), and what it reads is a jump (about 2° there) that
the smoothed path then spreads over a second on each side, a drift the viewer sees. Such
a pair's turn is taken from its neighbours' instead (:func:`stabilize.motion.repair`).

A pair is a cut where its two frames look alike nowhere and the flow agrees on nearly
nothing. Looking alike is the best normalised cross-correlation of the frames' blurred
grey thumbnails, each one's middle shifted over the other by up to 16% of its width and
height each way: a turn moves the picture, it does not replace it. On every pair of the
real clips here (cockatoo's bird covering the lens and its exposure jumps, hero7's walk,
the drones, phone-cc9's drive, the rendered sample) it read at least 0.86; across 360
cuts between those clips a median 0.31, at most 0.69, and 90% under ``LIKENESS``: a cut
between two pictures alike enough is left as it was. (Colour histograms could not tell
them apart: cockatoo's exposure jumps read a Bhattacharyya distance of 0.44 against a
cut's 0.65.) Thumbnails 96 px wide separate as 128 px ones do, and cost 0.2 ms a pair.

A cut between two shots of one place (karma's flight cut from its 4th second to its 8th:
0.916) looks alike enough, but far less alike than the pairs around it: its unlikeness,
1 - likeness, is 189 times the median of the 8 pairs' on each side (0.084 against
0.0004), and the vote read a 1.65° jump there. Such a pair is a cut too where it reads
under ``ALIKE`` and over ``DROP`` times its neighbours' median, and alone: a cut changes
the picture once, and the pairs beside it look as alike as their shot's others (each
under ``ALONE`` of its unlikeness), where a subject sweeping through the frame makes
several unlike pairs in a row (cockatoo's middle third, the bird's head swinging past:
0.896 then 0.934, and 0.721, 0.84, 0.719, 36-130 times their neighbours' unlikeness,
with none of the flow agreeing). The 21 of those 360 cuts that read over 0.6 read
0.60-0.82 and 28-397 times their neighbours' unlikeness; no pair of the real clips reads
over 14 (cockatoo's, at 0.908, with 3.7% of its flow agreeing), and of the pairs under
3%, over 8.2, nor any alone in their views at 640 px, zoomed in two or three times, at
half the frame rate or compressed at CRF 32.

A shot that resumes is not cut: a black frame dropped into karma's flight read two cuts,
into it and out of it, and three frames of hero7's walk with a hand across 70% of the
lens read one as the hand left; each shot was planned on its own, so the walk's zoom
jumped from 1.149 to 1.054 between two frames of one view. Where a pair looks unlike, its
later frame is compared with the ``RESUME`` frames before the pair's first, and where it
looks alike to one of them (``ALIKE`` or more), the pairs between are an interruption
(a flash, a dropped frame, something passing across the lens), not a cut: their turns
are their neighbours' mean, as a cut's (:mod:`stabilize.motion.repair`), but the path
goes on through them. Two shots of one place stay cut: karma's first second cut to its
fourth reads 0.906.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.motion.repair import MIN_SUPPORT
from stabilize.motion.track import VisualTrack

THUMBNAIL_WIDTH = 96  # px: the thumbnails compared
BLUR_PX = 0.75  # Gaussian σ of the thumbnails, px: noise and compression blocks do not count
SHIFT = 0.16  # of each thumbnail's width and height, each way, its middle shifts over the other
LIKENESS = 0.6  # the correlation under which two frames look alike nowhere
# grey levels (of 255): a thumbnail's middle of less contrast is blank (a black frame, a
# lens cap's noise), and two blank ones look alike, where every pair of a black clip was
# a cut; the real clips' frames read 23-67
BLANK = 1.0
ALIKE = 0.95  # ... and under which they may be a cut, far less alike than their neighbours
DROP = 25.0  # ... by this many times the median unlikeness of the NEIGHBOURS pairs each side
NEIGHBOURS = 8
ALONE = 0.25  # ... and alone: each pair beside it under this share of its unlikeness
# frames: the longest interruption a shot resumes after (0.27 s at 30 fps), each unlike
# pair's later frame compared with at most this many more. Frames of one shot look less
# alike further apart (at least: hero7's walk 0.964 four frames apart, 0.908 nine;
# karma 0.987, 0.959; phone-cc9's drive 0.930, 0.848), so a moving shot resumes ALIKE
# only after a shorter interruption
RESUME = 8


def thumbnail(frame: NDArray) -> NDArray[np.float32]:
    """A frame (RGB or grey) as a blurred grey thumbnail ``THUMBNAIL_WIDTH`` px wide."""
    grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY) if frame.ndim == 3 else frame
    h, w = grey.shape
    size = (THUMBNAIL_WIDTH, max(round(h * THUMBNAIL_WIDTH / w), 8))
    small = cv2.resize(grey, size, interpolation=cv2.INTER_AREA).astype(np.float32)
    return cv2.GaussianBlur(small, (0, 0), BLUR_PX)


def likeness(a: NDArray[np.float32], b: NDArray[np.float32]) -> float:
    """How alike two thumbnails look: the best normalised cross-correlation of either's
    middle over the other, shifted by up to ``SHIFT`` each way (1: the same picture, moved).

    >>> rng = np.random.default_rng(0)
    >>> picture = cv2.GaussianBlur(255 * rng.random((72, 160), np.float32), (0, 0), 2.0)
    >>> round(likeness(picture[:, :96], picture[:, 10:106]), 3)  # turned 10 px
    1.0
    >>> likeness(picture[:, :96], 255 * rng.random((72, 96), np.float32)) < LIKENESS
    True
    >>> black = np.full((72, 96), 16, np.float32)
    >>> likeness(black, black + rng.normal(0, 0.5, black.shape).astype(np.float32))
    1.0
    """
    h, w = a.shape
    dy, dx = round(h * SHIFT), round(w * SHIFT)
    middles = [one[dy : h - dy, dx : w - dx] for one in (a, b)]
    blank = [float(middle.std()) <= BLANK for middle in middles]
    if all(blank):  # nothing to tell them apart: no change of picture
        return 1.0
    best = -1.0
    for middle, other, flat in ((middles[0], b, blank[0]), (middles[1], a, blank[1])):
        if not flat:  # a blank picture matches nothing
            best = max(best, float(cv2.matchTemplate(other, middle, cv2.TM_CCOEFF_NORMED).max()))
    return best


def resumes_from(recent: Sequence[NDArray[np.float32]], after: NDArray[np.float32]) -> int:
    """How far back, beyond the frame just before it (the last of the ``recent``
    thumbnails, oldest first), the thumbnail ``after`` finds the farthest picture it looks
    alike to (``ALIKE`` or more): 2 where it is the frame two before; 0 where none is.

    >>> rng = np.random.default_rng(0)
    >>> view = cv2.GaussianBlur(255 * rng.random((54, 96), np.float32), (0, 0), 2.0)
    >>> black = np.zeros_like(view)
    >>> resumes_from([view, view, black], view)  # a black frame between
    3
    >>> resumes_from([view, black], 255 * rng.random((54, 96), np.float32))  # another picture
    0
    """
    for back in range(len(recent), 1, -1):
        if likeness(recent[-back], after) >= ALIKE:
            return back
    return 0


def interrupted(back: NDArray) -> NDArray[np.bool_]:
    """The pairs an interruption spans: for each pair k whose later frame resumes a
    picture ``back[k]`` frames back (:func:`resumes_from`), the pairs from that frame's
    to k.

    >>> interrupted(np.array([0, 0, 0, 3, 0]))  # frame 4 looks as frame 1 did
    array([False,  True,  True,  True, False])
    """
    spans = np.zeros(len(back) + 1, np.int64)
    for k in np.flatnonzero(back):
        spans[k + 1 - back[k]] += 1
        spans[k + 1] -= 1
    return np.cumsum(spans)[:-1] > 0


def shots(cuts: NDArray) -> list[tuple[int, int]]:
    """The shots, (first frame, stop) each, of a clip whose pairs (frames t, t + 1) that
    ``cuts`` marks are changes of shot. A shot of one frame (a flash between two cuts)
    goes with the shot after it (the last, with the one before): a path needs a pair.

    >>> shots(np.array([False, False, True, False]))  # frames 0-2 | 3-4
    [(0, 3), (3, 5)]
    >>> shots(np.array([False, True, True, False]))  # frame 2 alone joins 3-4
    [(0, 2), (2, 5)]
    """
    starts = [0]
    for pair in np.flatnonzero(np.asarray(cuts, bool)):
        if pair + 1 - starts[-1] >= 2:
            starts.append(int(pair) + 1)
    stop = len(cuts) + 1
    if len(starts) > 1 and stop - starts[-1] < 2:
        starts.pop()
    return list(zip(starts, [*starts[1:], stop], strict=True))


SAID = 10  # the cuts a notice names by their times


def said_cuts(times: NDArray) -> str:
    """The cuts at ``times`` (s: the first frame of each new shot) as a notice says them:
    one, or a montage's count, its first ``SAID`` times and how many more.

    >>> said_cuts(np.array([1.0]))
    'a cut (a change of shot) at 1.00 s'
    >>> said_cuts(np.arange(1, 13) / 2)[-33:]
    '4.00 s, 4.50 s, 5.00 s and 2 more'
    """
    at = ", ".join(f"{t:.2f} s" for t in times[:SAID])
    if len(times) == 1:
        return f"a cut (a change of shot) at {at}"
    more = f" and {len(times) - SAID} more" if len(times) > SAID else ""
    return f"{len(times)} cuts (changes of shot) at {at}{more}"


@dataclass(frozen=True)
class Breaks:
    """Where a track's pictures break. ``unrelated``: the pairs whose frames look
    unrelated and whose flow agrees on nothing (:func:`unrelated_pairs`), so no turn is
    read across them; ``cuts``: those of them where the shot changes rather than resumes
    (:func:`interrupted`), after which the path is planned anew."""

    unrelated: NDArray[np.bool_]
    cuts: NDArray[np.bool_]


def track_breaks(track: VisualTrack) -> Breaks:
    """A pass-1 track's :class:`Breaks`; none where its pictures' likeness was not
    measured."""
    if track.likeness is None:
        none = np.zeros(len(track.support), bool)
        return Breaks(none, none)
    unrelated = unrelated_pairs(track.likeness, track.support)
    resumed = np.zeros_like(unrelated) if track.resumes is None else interrupted(track.resumes)
    return Breaks(unrelated, unrelated & ~resumed)


def unrelated_pairs(likenesses: NDArray, support: NDArray) -> NDArray[np.bool_]:
    """Which frame pairs see unrelated pictures: under ``MIN_SUPPORT`` of the flow
    agrees on any rotation, and their frames look alike nowhere (``likenesses`` under
    ``LIKENESS``), or far less alike than the pairs around them (:func:`drops`).

    >>> alike = np.array([0.999, 0.998, 0.999, 0.91, 0.999, 0.997, 0.4])
    >>> unrelated_pairs(alike, np.full(7, 0.01))  # 0.91: 90 times its neighbours' unlikeness
    array([False, False, False,  True, False, False,  True])
    >>> unrelated_pairs(alike, np.full(7, 0.2))  # but most of the flow agrees on a turn
    array([False, False, False, False, False, False, False])
    """
    likenesses = np.asarray(likenesses, dtype=np.float64)
    unlike = (likenesses < LIKENESS) | drops(likenesses)
    return unlike & (np.asarray(support) < MIN_SUPPORT)


def drops(likenesses: NDArray) -> NDArray[np.bool_]:
    """Which pairs look far less alike than their neighbours: under ``ALIKE``, and
    unlike, 1 - likeness, over ``DROP`` times the median unlikeness of the
    ``NEIGHBOURS`` pairs on each side (fewer at the clip's ends; none: no drop), and
    alone: each pair beside it under ``ALONE`` of its unlikeness.

    >>> drops(np.array([0.999, 0.998, 0.9, 0.999, 0.999, 0.9, 0.95, 0.999, 0.998]))
    array([False, False,  True, False, False, False, False, False, False])
    """
    unlike = 1.0 - np.asarray(likenesses, dtype=np.float64)
    padded = np.pad(unlike, NEIGHBOURS, constant_values=np.nan)
    around = np.lib.stride_tricks.sliding_window_view(padded, 2 * NEIGHBOURS + 1).copy()
    around[:, NEIGHBOURS] = np.nan  # the pair itself
    counted = np.isfinite(around).any(axis=1)
    typical = np.full(len(unlike), np.inf)
    typical[counted] = np.nanmedian(around[counted], axis=1)
    beside = np.maximum(np.r_[0.0, unlike[:-1]], np.r_[unlike[1:], 0.0])
    return (unlike > 1.0 - ALIKE) & (unlike > DROP * typical) & (beside < ALONE * unlike)
