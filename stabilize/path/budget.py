"""Keeping the smoothed path within the crop budget.

Where the smooth path would need more zoom than ``max_zoom`` to hide every border, it
is bent back towards less smoothed paths (which still remove the fast shake), and last
towards the raw path, which needs no zoom. The pull is itself smoothed in time, so that
the bent path has no kinks that would read as jerks. A path (:class:`Trajectory`) is
the orientations S_t and the 2-D path q̃_t (:mod:`stabilize.path.residual`), bent
together by the same amount.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import sparse

from rotation import so3
from stabilize.path.smoothing import gaussian_band

PULL_STEP = 0.05  # how much each round of respect_zoom_budget adds to an over-budget pull
PULL_ROUNDS = 800
PULL_SIGMA = 0.5  # the pull's spread in time, as a share of the smoothing time constant


@dataclass(frozen=True)
class Trajectory:
    """A camera path: orientations ``turn`` S_t (N, 3, 3) and the 2-D path ``shift``
    q_t (N, 4) (:mod:`stabilize.path.residual`; zeros without one)."""

    turn: NDArray
    shift: NDArray

    def take(self, frames: NDArray | slice) -> Trajectory:
        return Trajectory(self.turn[frames], self.shift[frames])

    def towards(self, target: Trajectory, amount: NDArray) -> Trajectory:
        """Per frame, the fraction ``amount`` of the way to ``target`` (the turn
        geodesically, the 2-D path linearly)."""
        amount = np.asarray(amount, np.float64)
        shift = self.shift + (target.shift - self.shift) * amount[:, None]
        return Trajectory(blend(self.turn, target.turn, amount), shift)


# f(path, frames): a per-frame figure (the zoom needed, or whether it is over budget) for
# the frames (indices) of a path, given as those frames' part of it.
PerFrame = Callable[[Trajectory, NDArray], NDArray]


def blend(S: NDArray, O: NDArray, amount: NDArray) -> NDArray[np.float64]:
    """Per frame, move S_t the fraction ``amount`` of the way to O_t (geodesically)."""
    step = so3.log_so3(O @ np.swapaxes(S, -1, -2)) * np.asarray(amount)[:, None]
    return so3.exp_so3(step) @ S


def respect_zoom_budget(
    raw: Trajectory,
    path: Trajectory,
    times: NDArray,
    zoom_of: PerFrame,
    max_zoom: float,
    smooth: float,
    via: Sequence[Trajectory] = (),
    over: PerFrame | None = None,
) -> tuple[Trajectory, NDArray]:
    """Bend the smooth ``path`` where it would need more than max_zoom.

    ``zoom_of(part, frames)`` gives the zoom that each of ``frames`` (indices) needs on
    a path whose part at those frames is ``part``; ``over(part, frames)``, whether each
    needs more than max_zoom (by default from zoom_of; a direct check at max_zoom is
    much cheaper than a zoom search). The path is bent towards each of ``via`` in turn
    (less smoothed paths: they still remove the fast shake and only follow the slower
    motion closer), and last towards the ``raw`` path, which needs no zoom, so this
    ends. Returns (path, per-frame zoom).
    """
    everything = np.arange(len(path.turn))
    if over is None:

        def over(part: Trajectory, frames: NDArray) -> NDArray:
            return zoom_of(part, frames) > max_zoom

    zoom = zoom_of(path, everything)
    for target in (*via, raw):
        if (zoom > max_zoom).any():
            path = _bend(path, target, times, over, zoom > max_zoom, smooth)
            zoom = zoom_of(path, everything)
    if (zoom > max_zoom).any():  # the rounds ran out before the raw path was reached
        return raw, zoom_of(raw, everything)
    return path, zoom


def _bend(
    path: Trajectory,
    target: Trajectory,
    times: NDArray,
    over: PerFrame,
    is_over: NDArray,
    smooth: float,
) -> Trajectory:
    """Pull ``path`` towards ``target`` where the zoom is over budget (``is_over``), the
    pull itself smoothed in time (so the path stays smooth), growing until no frame is
    over or it is full."""
    amount = np.zeros(len(path.turn))
    turn, shift = path.turn.copy(), path.shift.copy()
    sigma = max(smooth, 1e-3) * PULL_SIGMA
    # Cut at 4σ, so that a round changes the path, and costs a check, only near the
    # frames over budget.
    g = gaussian_band(times, sigma)
    g = sparse.diags_array(1.0 / g.sum(axis=1)) @ g
    spread = np.zeros(len(turn))
    is_over = is_over.copy()
    for _ in range(PULL_ROUNDS):
        if not is_over.any() or spread[is_over].min() >= 1.0:
            break
        # The pull grows where the budget is broken and is spread by a normalised
        # Gaussian in time: smooth (no kinks that would read as jerks), and where it is
        # too thin to help it keeps growing until it does.
        amount += PULL_STEP * is_over
        grown = np.clip(g @ amount, 0.0, 1.0)
        changed = np.flatnonzero(grown != spread)
        spread = grown
        part = path.take(changed).towards(target.take(changed), spread[changed])
        turn[changed], shift[changed] = part.turn, part.shift
        is_over[changed] = over(part, changed)
    return Trajectory(turn, shift)
