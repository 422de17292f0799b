"""The visual estimate of a clip: one rotation per frame pair, and where it was seen.

Under a rolling shutter the rows of a frame are captured one after another, row y at
``t + readout · y/H``. A rotation measured from flow vectors around height ȳ therefore
belongs to the times ``t_k + readout · ȳ`` and ``t_{k+1} + readout · ȳ``, not to the frame
times themselves. ``rows`` keeps ȳ per pair (0 top, 1 bottom) for that reason, and
``bands`` the rotations measured from separate horizontal bands of the frame, from which
the readout time can be estimated (:func:`stabilize.gyro.sync.estimate_readout`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from rotation.refine import refine
from stabilize.motion.residual import landing

MIN_BAND_SUPPORT = 0.05  # a band with so few agreeing vectors says little about its time
# px at the flow's size: a vector that lands this close to where a rotation puts its point
# agrees with that rotation (the focal search's outlier cost starts at the same distance)
AGREE_PX = 1.5
# px at the flow's size: a rotation refined from a guess starts from the vectors that land
# this close to where the guess puts them. Twice the agreement's distance: a hand's shake
# moved cockatoo's static scene 2–3 px a frame off its neighbours' mean (its pair 59,
# repaired from 2 px, stayed 3 px off what the window behind the bird moved; from 3 or
# 4.5 px, 0.9 and 1.0 px off)
REFINE_FROM_PX = 2 * AGREE_PX


@dataclass(frozen=True)
class Samples:
    """The flow vectors pass 1 read at the estimator's sample grid, kept (float32, about
    5 KB a pair) so that the rotations can be estimated again without decoding: with
    another focal length (:mod:`stabilize.motion.focal`), or what they leave measured
    again once a rolling shutter's rows are dated (:mod:`stabilize.shutter.residual`).
    The rotations are voted from the flow's vectors; what they leave is measured on the
    same vectors refined by Lucas–Kanade (:func:`flow.refine.refine_at`), where kept."""

    u: NDArray[np.float32]  # (N-1, M)
    v: NDArray[np.float32]
    valid: NDArray[np.bool_]  # finite: the bands and the focal length's search use these
    # the grid: (M,) points about the principal point and their rows, flow px
    x: NDArray[np.float64] | None = None
    y: NDArray[np.float64] | None = None
    rows: NDArray[np.float64] | None = None
    height: int = 0  # the flow field's, px
    scale: float = 1.0  # flow px per input px (the estimator's focal is f·scale)
    # the valid vectors where the first frame had the texture to measure (flow.texture):
    # these vote for the frame's rotation and measure what it leaves (None: every valid one)
    measured: NDArray[np.bool_] | None = None
    # (N-1, M) each the same vectors refined by Lucas–Kanade at the working size, for
    # what the rotation leaves (:mod:`stabilize.motion.residual`); None: the flow's
    fine_u: NDArray[np.float32] | None = None
    fine_v: NDArray[np.float32] | None = None

    def pairs(self, first: int, stop: int) -> Samples:
        """The pairs first..stop-1."""
        part = slice(first, stop)

        def cut(a: NDArray | None) -> NDArray | None:
            return None if a is None else a[part]

        return replace(
            self,
            u=self.u[part],
            v=self.v[part],
            valid=self.valid[part],
            measured=cut(self.measured),
            fine_u=cut(self.fine_u),
            fine_v=cut(self.fine_v),
        )

    @property
    def fine(self) -> tuple[NDArray, NDArray]:
        """(u, v) (N-1, M) of the vectors what a rotation leaves is measured on: refined
        where they were, else the flow's."""
        if self.fine_u is None or self.fine_v is None:
            return self.u, self.v
        return self.fine_u, self.fine_v

    @property
    def voting(self) -> NDArray[np.bool_]:
        """The vectors that vote for a pair's rotation and measure what it leaves."""
        return self.valid if self.measured is None else self.measured

    def agreeing(self, pair: int, R: NDArray, focal: float) -> int:
        """How many of pair ``pair``'s voting vectors land within ``AGREE_PX`` of where the
        rotation R (3, 3) puts their points, at ``focal`` (px of the input frames)."""
        f = focal * self.scale
        lx, ly = landing(self.x, self.y, np.asarray(R, np.float64)[None], f)
        miss = np.hypot(self.x + self.u[pair] - f * lx[0], self.y + self.v[pair] - f * ly[0])
        return int(np.count_nonzero(self.voting[pair] & (miss < AGREE_PX)))

    def refined(self, pair: int, R: NDArray, focal: float) -> NDArray[np.float64]:
        """The rotation (3, 3) pair ``pair``'s voting vectors settle on from the guess R
        (:func:`rotation.refine.refine`, starting from those within ``REFINE_FROM_PX``
        of where R puts their points), at ``focal`` (px of the input frames): the motion
        of whatever moves nearest the guess."""
        f = focal * self.scale
        qx = self.x + self.u[pair].astype(np.float64)
        qy = self.y + self.v[pair].astype(np.float64)
        guess = np.asarray(R, np.float64)
        return refine(self.x, self.y, qx, qy, f, guess, self.voting[pair], REFINE_FROM_PX)


@dataclass(frozen=True)
class VisualTrack:
    times: NDArray[np.float64]  # (N,) s, video clock: when each frame's first row is captured
    rotations: NDArray[np.float64]  # (N-1, 3, 3) R_t
    support: NDArray[np.float64]  # (N-1,) share of the flow vectors that agree
    rows: NDArray[np.float64]  # (N-1,) mean height of those vectors, 0 top .. 1 bottom
    bands: NDArray[np.float64] | None = None  # (B, N-1, 3, 3) R_t from each band alone
    band_rows: NDArray[np.float64] | None = None  # (B, N-1) their mean heights
    band_support: NDArray[np.float64] | None = None  # (B, N-1)
    samples: Samples | None = None  # the flow vectors read, where kept
    # (N-1, 4) the similarity (dx, dy, a, b) left after each rotation, normalised image
    # coordinates (:mod:`stabilize.motion.residual`)
    residual: NDArray[np.float64] | None = None
    # (N-1,) how alike each pair's frames look, 1 the same picture (:mod:`.cuts`)
    likeness: NDArray[np.float64] | None = None
    # (N-1,) of a pair whose frames look unlike, how far back its later frame finds a
    # picture it looks alike to: the shot resumed after an interruption (:mod:`.cuts`)
    resumes: NDArray[np.int64] | None = None
    # at a high frame rate, the flow vectors between frames ``every`` apart (frames 0,
    # K, 2K, ...): a stride's pair each (:mod:`.strides`); None, and 1, below 45 fps
    strides: Samples | None = None
    every: int = 1
    # (N-1, 4) what holding the pairs to their strides added to each one's residual, to
    # add again where the residual is measured anew (under a rolling shutter)
    held: NDArray[np.float64] | None = None
    # the strides voted (a pair each, frames 0, K, 2K, ...; their bands where the pairs
    # have them): a rolling shutter's readout is searched on them (:mod:`.strides`)
    stride_track: VisualTrack | None = None

    @classmethod
    def from_rotations(cls, times: NDArray, rotations: NDArray) -> VisualTrack:
        """A track without row information (the middle row for every pair)."""
        rotations = np.asarray(rotations, dtype=np.float64)
        n = len(rotations)
        return cls(np.asarray(times, np.float64), rotations, np.ones(n), np.full(n, 0.5))

    def pairs(self, first: int, stop: int) -> VisualTrack:
        """The pairs first..stop-1 (frames first..stop)."""
        cut = (lambda a: None) if self.bands is None else (lambda a: a[:, first:stop])
        return VisualTrack(
            self.times[first : stop + 1],
            self.rotations[first:stop],
            self.support[first:stop],
            self.rows[first:stop],
            cut(self.bands),
            cut(self.band_rows),
            cut(self.band_support),
            None if self.samples is None else self.samples.pairs(first, stop),
            None if self.residual is None else self.residual[first:stop],
            None if self.likeness is None else self.likeness[first:stop],
            None if self.resumes is None else self.resumes[first:stop],
        )

    def spliced(self, first: int, part: VisualTrack) -> VisualTrack:
        """The track with its pairs from ``first`` on measured again as ``part`` says
        (its rotations, support, rows, bands and residual; a shot voted at its own focal
        length): the flow vectors and what the pictures said are the same."""

        def put(mine: NDArray | None, theirs: NDArray | None, axis: int = 0) -> NDArray | None:
            if mine is None or theirs is None:
                return mine
            out = mine.copy()
            index = [slice(None)] * out.ndim
            index[axis] = slice(first, first + theirs.shape[axis])
            out[tuple(index)] = theirs
            return out

        return replace(
            self,
            rotations=put(self.rotations, part.rotations),
            support=put(self.support, part.support),
            rows=put(self.rows, part.rows),
            bands=put(self.bands, part.bands, 1),
            band_rows=put(self.band_rows, part.band_rows, 1),
            band_support=put(self.band_support, part.band_support, 1),
            residual=put(self.residual, part.residual),
        )


def mean_rows(inliers: NDArray[np.bool_], sample_rows: NDArray, height: int) -> NDArray:
    """Mean height (0 top .. 1 bottom) of the flow vectors that agreed with each of a
    stack of estimates, from their inlier masks (n, rows, cols) on the sample grid's
    rows ``sample_rows``; 0.5 where none agreed."""
    per_row = inliers.sum(axis=2)
    total = per_row.sum(axis=1)
    weighted = (per_row * (np.asarray(sample_rows) + 0.5)).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, weighted / total / height, 0.5)
