"""Smoothing the camera's orientation path on SO(3) (never on Euler angles).

Orientations O_t (world → camera) are averaged in the tangent space of each frame:

    S_t = exp( Σ_j w_tj log(O_j O_tᵀ) ) O_t,     Σ_j w_tj = 1,

one Gauss-Newton step of the weighted Karcher mean, which is exact enough at the small
angles a hand covers within a smoothing window. The weights are a Gaussian in time
(zero phase: no lag), with σ = ``smooth`` seconds.

``adaptive`` narrows the window where the camera turns fast, so intentional pans are
followed closely while shake is still removed (the idea of Gyroflow's default). ``lock``
holds one orientation, as on a tripod.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray
from scipy import sparse

from rotation import so3

METHODS = ("adaptive", "gaussian", "lock")
ADAPTIVE_REF_DEG_S = 30.0  # angular speed at which the window halves
PULL_STEP = 0.05  # how much each round of respect_zoom_budget adds to an over-budget pull
PULL_ROUNDS = 800
PULL_SIGMA = 0.5  # the pull's spread in time, as a share of the smoothing time constant

# f(path, frames): a per-frame figure (the zoom needed, or whether it is over budget) for
# the frames (indices) of a path (N, 3, 3).
PerFrame = Callable[[NDArray, NDArray], NDArray]


def gaussian_band(times: NDArray, sigma: float, reach: float = 4.0) -> sparse.csr_array:
    """g_ij = exp(-½ ((t_i - t_j) / σ)²) for |t_i - t_j| ≤ reach·σ, else 0: an (N, N)
    sparse matrix over sorted ``times``, whose memory grows with the clip's length, not
    with its square (a dense one would need 2.6 GB for ten minutes at 30 fps).

    >>> gaussian_band(np.arange(5) / 30, 0.01).nnz  # each frame, and its neighbours
    13
    """
    times = np.asarray(times, dtype=np.float64)
    n = len(times)
    lo = np.searchsorted(times, times - reach * sigma)
    hi = np.searchsorted(times, times + reach * sigma, side="right")
    counts = hi - lo
    rows = np.repeat(np.arange(n), counts)
    starts = np.repeat(np.cumsum(counts) - counts, counts)  # each row's first entry
    cols = np.repeat(lo, counts) + np.arange(counts.sum()) - starts
    weights = np.exp(-0.5 * ((times[rows] - times[cols]) / sigma) ** 2)
    return sparse.csr_array((weights, (rows, cols)), shape=(n, n))


def _gaussian_mean(O: NDArray, times: NDArray, sigma: NDArray) -> NDArray:
    n = len(O)
    out = np.empty_like(O)
    for t in range(n):
        s = max(float(sigma[t]), 1e-6)
        lo = np.searchsorted(times, times[t] - 3 * s)
        hi = np.searchsorted(times, times[t] + 3 * s, side="right")
        w = np.exp(-0.5 * ((times[lo:hi] - times[t]) / s) ** 2)
        w /= w.sum()
        tangent = so3.log_so3(O[lo:hi] @ O[t].T)
        out[t] = so3.exp_so3(w @ tangent) @ O[t]
    return out


def angular_speed(O: NDArray, times: NDArray) -> NDArray:
    """|ω| per frame in rad/s, from consecutive orientations (last repeated)."""
    if len(O) < 2:
        return np.zeros(len(O))
    R = O[1:] @ np.swapaxes(O[:-1], -1, -2)
    speed = so3.angle(R) / np.maximum(np.diff(times), 1e-6)
    return np.append(speed, speed[-1])


def smooth_orientations(
    O: NDArray, times: NDArray, smooth: float = 0.5, method: str = "adaptive"
) -> NDArray[np.float64]:
    """The smoothed path S_t for orientations O_t (N, 3, 3) at ``times`` (s)."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    O = np.asarray(O, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    if method == "lock":
        # Hold the mean orientation: it needs less zoom than holding the first one.
        mean = so3.exp_so3(so3.log_so3(O @ O[0].T).mean(axis=0)) @ O[0]
        return np.broadcast_to(mean, O.shape).copy()
    if len(O) < 2:
        return O.copy()
    sigma = np.full(len(O), float(smooth))
    if method == "adaptive":
        # The slow component of the motion decides how wide the window may be.
        slow = _gaussian_mean(O, times, sigma)
        speed = np.degrees(angular_speed(slow, times))
        sigma = smooth / (1.0 + speed / ADAPTIVE_REF_DEG_S)
        sigma = np.convolve(np.pad(sigma, 2, mode="edge"), np.ones(5) / 5, mode="valid")
    return _gaussian_mean(O, times, sigma)


def orientations_from_rotations(R: NDArray) -> NDArray[np.float64]:
    """O_0 = I and O_{t+1} = R_t O_t, for frame-to-frame rotations R_t (N-1, 3, 3)."""
    O = np.empty((len(R) + 1, 3, 3))
    O[0] = np.eye(3)
    for k, r in enumerate(R):
        O[k + 1] = r @ O[k]
    return O


def blend(S: NDArray, O: NDArray, amount: NDArray) -> NDArray[np.float64]:
    """Per frame, move S_t the fraction ``amount`` of the way to O_t (geodesically)."""
    step = so3.log_so3(O @ np.swapaxes(S, -1, -2)) * np.asarray(amount)[:, None]
    return so3.exp_so3(step) @ S


def respect_zoom_budget(
    O: NDArray,
    S: NDArray,
    times: NDArray,
    zoom_of: PerFrame,
    max_zoom: float,
    smooth: float,
    via: Sequence[NDArray] = (),
    over: PerFrame | None = None,
) -> tuple[NDArray, NDArray]:
    """Bend the smooth path where it would need more than max_zoom.

    ``zoom_of(S, frames)`` gives the zoom that each of ``frames`` (indices) needs on the
    path S (N, 3, 3); ``over(S, frames)``, whether each needs more than max_zoom (by
    default from zoom_of; a direct check at max_zoom is much cheaper than a zoom
    search). The path is bent towards each of ``via`` in turn (less smoothed paths:
    they still remove the fast shake and only follow the slower motion closer), and
    last towards the raw path O, which needs no zoom, so this ends. Returns (S,
    per-frame zoom).
    """
    everything = np.arange(len(S))
    if over is None:

        def over(path: NDArray, frames: NDArray) -> NDArray:
            return zoom_of(path, frames) > max_zoom

    zoom = zoom_of(S, everything)
    for target in (*via, O):
        if (zoom > max_zoom).any():
            S = _bend(S, target, times, over, zoom > max_zoom, smooth)
            zoom = zoom_of(S, everything)
    if (zoom > max_zoom).any():  # the rounds ran out before the raw path was reached
        return O.copy(), zoom_of(O, everything)
    return S, zoom


def _bend(
    S: NDArray, target: NDArray, times: NDArray, over: PerFrame, is_over: NDArray, smooth: float
) -> NDArray:
    """Pull S towards ``target`` where the zoom is over budget (``is_over``), the pull
    itself smoothed in time (so the path stays smooth), growing until no frame is over
    or it is full."""
    amount = np.zeros(len(S))
    bent = S.copy()
    sigma = max(smooth, 1e-3) * PULL_SIGMA
    # Cut at 4σ, so that a round changes the path, and costs a check, only near the
    # frames over budget.
    g = gaussian_band(times, sigma)
    g = sparse.diags_array(1.0 / g.sum(axis=1)) @ g
    spread = np.zeros(len(S))
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
        bent[changed] = blend(S[changed], target[changed], spread[changed])
        is_over[changed] = over(bent[changed], changed)
    return bent
