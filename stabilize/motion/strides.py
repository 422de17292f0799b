"""High frame rates: the pairs' turns held to the turn measured a stride of frames apart.

At 240 fps a pair turns an eighth of what it turns at 30 fps, and its estimate is not
eight times finer: on a rendered 240 fps walk each pair read 0.009° off the truth against
0.022° at 30 fps, and since a walk's parallax errs the same way pair after pair, the
eight pairs of each thirtieth of a second added up to 0.048° (a 30 fps pair's 0.022).
What a viewer sees at real speed, the output's shake per thirtieth of a second, was 1.31
px against 0.49 for the same walk rendered at 30 fps.

So where the frames come ``every`` ≥ 2 to a thirtieth of a second (:func:`stride_for`),
pass 1 also measures the flow from frame jK to frame (j+1)K, one field more per K pairs,
and votes its rotation S_j. The K pairs between are bent to compose to it: with their
chain C_j = R_{jK+K-1} ··· R_{jK} and its miss d_j = log(S_j C_jᵀ), each pair turns by
exp(d_j / K) more (twice, so that the non-commuting remainder vanishes):

    R'_t = exp(d_j / K) · R_t,      jK ≤ t < (j+1)K,

the least-squares bend when the pairs' errors are alike, which a walk's are. The
similarity each pair leaves (:mod:`stabilize.motion.residual`) is held to the stride's
alike, r'_t = r_t + (s_j - Σ r_t)/K: a change of a pair's turn changes its remainder by
the same image motion as the chain's. The bands keep their offsets from their pair.

A stride is used only where it can speak for its pairs: its own support is no lower than
a pair's must be (:mod:`stabilize.motion.repair`), every pair it spans looks alike and
is supported (no cut, interruption or subject winning the vote inside), and its miss
lies within ``MAX_MISS_DEG``. Elsewhere the pairs stay as voted; the repair sees them.

The focal length is searched on the strides (:mod:`stabilize.motion.focal`), and so is
a rolling shutter's readout (:mod:`stabilize.shutter.readout`): a 240 fps pair turns too
little to show either.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from rotation import HoughEstimator, so3
from stabilize.motion.cuts import ALIKE
from stabilize.motion.estimate import estimate_again
from stabilize.motion.repair import support_bar
from stabilize.motion.track import VisualTrack

# The rate strides bring a clip's pairs down to, frames per second: a stride spans a
# thirtieth of a second, what a 30 fps pair does.
STRIDE_FPS = 30.0
# A chain of a thirtieth of a second whose turn misses its stride's by more than this is
# not the stride's fault to mend: the rendered 240 fps walk's missed by 0.05° on average
MAX_MISS_DEG = 0.5
BENDS = 2  # rounds of the bend: the second takes the first's non-commuting remainder


def stride_for(fps: float) -> int:
    """How many pairs a stride spans at ``fps``: the frames to a thirtieth of a second,
    rounded; 1 (no strides) below 45 fps."""
    return max(1, round(fps / STRIDE_FPS)) if fps > 0 else 1


def within(first: int, stop: int, every: int) -> tuple[int, int]:
    """The strides (j0, j1: j0..j1-1) of ``every`` pairs that lie within frames
    first..stop-1."""
    return -(-first // every), (stop - 1) // every


def strided_track(
    track: VisualTrack, estimator: HoughEstimator, bands: int = 0
) -> VisualTrack | None:
    """The track of the strides pass 1 measured (:attr:`VisualTrack.strides`), voted by
    ``estimator``: one pair per stride, frames 0, K, 2K, ..., with their samples (and
    ``bands`` bands each); None where there are none."""
    strides, every = track.strides, track.every
    if strides is None or every < 2 or len(strides.u) == 0:
        return None
    count = len(strides.u)
    times = track.times[: count * every + 1 : every]
    blank = VisualTrack.from_rotations(times, np.broadcast_to(np.eye(3), (count, 3, 3)))
    return estimate_again(estimator, replace(blank, samples=strides), bands)


def held_to_strides(track: VisualTrack, strided: VisualTrack | None) -> VisualTrack:
    """The track with each usable stride's pairs bent to compose to its turn, and their
    similarities to its (module docstring); as it is where there is no stride."""
    if strided is None:
        return track
    every = track.every
    R = np.array(track.rotations, np.float64, copy=True)
    bands = None if track.bands is None else np.array(track.bands, copy=True)
    held = None if track.residual is None else np.zeros_like(track.residual)
    for j in np.flatnonzero(usable(track, strided)):
        part = slice(j * every, (j + 1) * every)
        step = np.eye(3)
        for _ in range(BENDS):
            miss = so3.log_so3((strided.rotations[j] @ chain(R[part]).T)[None])[0]
            bend = so3.exp_so3((miss / every)[None])[0]
            R[part] = bend @ R[part]
            step = bend @ step
        if bands is not None:
            bands[:, part] = step @ bands[:, part]
        if held is not None and strided.residual is not None:
            held[part] = (strided.residual[j] - track.residual[part].sum(axis=0)) / every
    residual = None if held is None else track.residual + held
    return replace(
        track, rotations=R, residual=residual, bands=bands, held=held, stride_track=strided
    )


def usable(track: VisualTrack, strided: VisualTrack) -> NDArray[np.bool_]:
    """Which strides speak for their pairs (module docstring)."""
    every, count = track.every, len(strided.rotations)
    pairs = slice(0, count * every)
    supported = (track.support[pairs] >= support_bar(track.support)).reshape(count, every)
    alike = np.ones((count, every), bool)
    if track.likeness is not None:
        alike = (track.likeness[pairs] >= ALIKE).reshape(count, every)
    chains = np.stack([chain(track.rotations[j * every : (j + 1) * every]) for j in range(count)])
    misses = so3.angle(strided.rotations @ np.swapaxes(chains, -1, -2))
    return (
        (strided.support >= support_bar(strided.support))
        & supported.all(axis=1)
        & alike.all(axis=1)
        & (np.degrees(misses) <= MAX_MISS_DEG)
    )


def chain(R: NDArray) -> NDArray[np.float64]:
    """The turn of consecutive pairs R (K, 3, 3) together: R_{K-1} ··· R_0."""
    out = np.eye(3)
    for step in R:
        out = step @ out
    return out
