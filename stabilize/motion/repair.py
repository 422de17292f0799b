"""Repairing the frames whose rotation too few flow vectors agreed on, and that jump.

A close moving subject can fill the frame and win the vote with a handful of vectors;
one such frame is a jump in the path that the smoothing then has to zoom around. A frame
whose support is low is repaired only if it also jumps: if its rotation vector lies
further from the mean of the reliable frames within ``REPAIR_WINDOW`` than
``JUMP_SPREADS`` times their own spread about that mean (and more than ``MIN_JUMP_DEG``);
it is then replaced by that mean (or by the nearest reliable frame's rotation).

Low support alone is no reason: motion blur and near walls lower it while the estimate
stays right. On a rendered 30° walk the five frames of least support (0.13–0.15, a
quarter of the median) were within 0.02–0.09° of the truth; replaced by their
neighbours' mean they were 0.47–0.95° off, since a walk's shake changes its direction
within three frames, and the residual shake of the output rose from 6.43 to 7.77 px.

A jump with low support is no proof either: a jolt blurs the frames it shakes. Where the
pair's flow vectors are at hand, the repair is the rotation they settle on when refined
from the neighbours' mean (:meth:`stabilize.motion.track.Samples.refined`): the static
scene's own motion in that frame, its shake included, which the mean smooths away. The
jump is kept where that refinement settles nearer the jump than the mean (the scene
moved with it), or where more vectors, and at least ``MIN_AGREEING``, agree with the
jump than with the repair. A subject that won the vote leaves the static scene agreeing
with the repair; after a jolt, the scene agrees with the jump.

On cockatoo, where the beak fills the frame and 2–5% of the vectors agree on any
rotation, the window behind the bird (its patch registered by phase correlation) moved
(-6.1, 0.0) px at the flow's size in pair 55: the vote read (8.5, -4.2), the
neighbours' mean (-4.5, 1.3), the refined repair (-6.0, 0.2); in pair 59 (-1.8, 2.7)
against (-8.5, 8.8), (-4.5, 1.3) and (-2.5, 2.1). The clip's residual shake went from
14.20 to 13.70 px (vid.stab 13.72), the mean of its mirrored readings from 14.64 to
13.84. Bird jumps the flow still follows with more vectors than the window has (pairs
56 and 63: 30 and 48 against 27 and 23) are kept.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.motion.track import VisualTrack

MIN_SUPPORT = 0.03  # below this share of agreeing vectors a frame's rotation is a guess
RELATIVE_SUPPORT = 0.35  # ...or below this fraction of the clip's median support
REPAIR_WINDOW = 3  # frames on each side whose rotations stand in for an unreliable one
JUMP_SPREADS = 3.0  # a low-support frame this many neighbour spreads off their mean jumps
MIN_JUMP_DEG = 0.2  # ...and at least this far (a steady camera's spread is ~0)
# the fewest flow vectors that must agree with a jump for the flow to prove it (4% of the
# estimator's 576): cockatoo's 10.8° jump, when the bird covered the lens, had 7
MIN_AGREEING = 24


def repair_unreliable(
    R: NDArray,
    support: NDArray,
    agreeing: Callable[[int, NDArray], int] | None = None,
    refined: Callable[[int, NDArray], NDArray] | None = None,
    unrelated: NDArray | None = None,
) -> tuple[NDArray, NDArray]:
    """Replace the rotations R (N-1, 3, 3) whose ``support`` is too low and that jump
    away from their neighbours', unless ``agreeing(k, R)``, how many of pair k's flow
    vectors a rotation R (3, 3) explains, finds more for the jump than for the repair.
    The repair is ``refined(k, mean)``, the rotation pair k's own vectors settle on from
    the neighbours' mean, where more of them agree with it than with the mean; else the
    mean.

    A pair marked ``unrelated`` (a cut, or a shot interrupted: a black frame, a flash,
    a hand across the lens; :mod:`stabilize.motion.cuts`) is the neighbours' mean
    whatever its vectors say: they see two unrelated pictures.

    Returns (R, reliable mask); all frames count as reliable when none, or all, are
    short of support, unrelated pairs aside.
    """
    support = np.asarray(support)
    blind = np.zeros(len(R), bool) if unrelated is None else np.asarray(unrelated, bool)
    supported = support >= support_bar(support)
    # short of support, where support tells pairs apart (some have it, some do not)
    doubtful = ~supported if supported.any() else np.zeros(len(R), bool)
    if not (doubtful.any() or blind.any()) or blind.all():
        return R, np.ones(len(R), bool)
    rotvecs = so3.log_so3(R)
    good = np.flatnonzero(~doubtful & ~blind)
    out = rotvecs.copy()
    reliable = np.ones(len(R), bool)  # a frame is unreliable once it is repaired
    for k in np.flatnonzero(doubtful | blind):
        near = good[np.abs(good - k) <= REPAIR_WINDOW]
        if near.size == 0:
            near = good[[np.argmin(np.abs(good - k))]]
        mean = rotvecs[near].mean(axis=0)
        if blind[k]:
            out[k], reliable[k] = mean, False
            continue
        spread = np.sqrt(np.mean(np.sum((rotvecs[near] - mean) ** 2, axis=1)))
        jump = np.linalg.norm(rotvecs[k] - mean)
        if jump <= max(JUMP_SPREADS * spread, np.radians(MIN_JUMP_DEG)):
            continue
        repair = mean
        if agreeing is not None:
            guess = so3.exp_so3(mean)
            agree = agreeing(k, guess)
            if refined is not None:
                R_settled = refined(k, guess)
                settled = so3.log_so3(R_settled[None])[0]
                if np.linalg.norm(settled - rotvecs[k]) < np.linalg.norm(settled - mean):
                    continue  # from the neighbours' motion the flow settles on the jump
                agree_settled = agreeing(k, R_settled)
                if agree_settled > agree:
                    repair, agree = settled, agree_settled
            follows = agreeing(k, R[k])
            if follows >= MIN_AGREEING and follows > agree:
                continue  # the flow follows the jump: a jolt
        out[k], reliable[k] = repair, False
    return so3.exp_so3(out), reliable


def support_bar(support: NDArray) -> float:
    """The support a vote needs to count among votes of ``support``: ``MIN_SUPPORT``,
    and ``RELATIVE_SUPPORT`` of their median."""
    return max(MIN_SUPPORT, RELATIVE_SUPPORT * float(np.median(support)))


def repair_track(
    track: VisualTrack, focal: float | NDArray, unrelated: NDArray | None = None
) -> tuple[NDArray, NDArray]:
    """:func:`repair_unreliable` on a pass-1 track, its own flow vectors (where it kept
    them) checking each jump at the focal length ``focal`` (px, full size; or each
    pair's, (N-1,)): the turns the stabiliser follows, before any rolling shutter's rows
    are dated."""
    samples = track.samples
    if samples is None:
        return repair_unreliable(track.rotations, track.support, unrelated=unrelated)
    each = np.broadcast_to(np.asarray(focal, np.float64), (len(track.rotations),))

    def agreeing(k: int, R: NDArray) -> int:
        return samples.agreeing(k, R, float(each[k]))

    def refined(k: int, R: NDArray) -> NDArray:
        return samples.refined(k, R, float(each[k]))

    return repair_unreliable(track.rotations, track.support, agreeing, refined, unrelated)
