"""The focal length from rotational flow alone.

A camera turning by ω moves a pixel p = (x, y) (relative to the principal point) by

    u ≈ -ωx·xy/f + ωy·(f + x²/f) - ωz·y,      v ≈ -ωx·(f + y²/f) + ωy·xy/f + ωz·x,

so f shows in the quadratic terms at the frame's edges: with a wrong f no rotation
explains both the middle and the edges, and the best fit leaves a residual that grows
with the turn, ∝ ω·(1/f - 1/f_true).

Walking forward over a ground plane leaves a residual of the same shape (its flow is
x·y·T/(f h) and y²·T/(f h)), which would bias f. But the two differ in time: a hand's
shake turns the camera back and forth from frame to frame, while the walk's flow is
the same from one frame to the next. So each pair's residual field d_t(i) is compared
with its own running mean over ±``WINDOW`` pairs (the slow, translation part), and only
what changes from frame to frame is scored:

    C(f) = Σ_t Σ_i min(|d_t(i) - d̄_t(i)|², c²),      c = ``CLIP_PX``,

each pair's rotation fitted again at f (Gauss-Newton from the estimate made at f₀, its
pitch and yaw scaled by f₀/f). The truncation keeps moving people and bad flow from
steering the fit. The minimum over a coarse log grid of f, then a fine one, refined by a
parabola, is the estimate; a curve without a clear interior minimum (a tripod, pure
roll, too little motion), one that lies flat on one side of it, or a shallow one (a
subject filling the frame, whose flow no focal length explains much better), gives none.
A deep curve that gives none can still rule a focal length out, one it reads well above
its floor (:meth:`FocalEstimate.rules_out`): a narrow lens's lies flat over the long focal
lengths, where its x²/f terms are too small to tell apart, and rises steeply on the wide
side.

The coarse grid only has to find the minimum's neighbourhood and whether there is one,
so it reads C on every ``THIN``-th sample, each rotation refitted in ``COARSE_ROUNDS``
rounds; the fine grid reads it exactly, walking downhill from the coarse minimum. On the
1080p, 10 s bench clip the search took 0.58 s when both grids read C exactly at every
candidate, and takes 0.2 s so.
"""

from __future__ import annotations

import itertools
import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np
from numba import get_num_threads, njit
from numpy.typing import NDArray

from rotation.refine import refine, rodrigues, rotate_ray

CLIP_PX = 1.5  # residuals beyond this many pixels count as outliers, at a fixed cost
GATE_PX = 3.0  # the first robust scale of each refit
WINDOW = 15  # pairs on each side of the running median that holds the walk's parallax
STRIDE = 5  # pairs between the running median's evaluations
# The curve's minimum must lie this share below its highest point (FocalEstimate.depth):
# where it lies less, no focal length explains the flow much better than another, and
# the minimum wanders. On cockatoo (a bird filling the frame) the coarse curve fell 9-14%
# and its minimum read 968-1740 px, or nothing, as the coarse grid's reading changed
# (every second, third or fourth sample, two refit rounds or six); every clip whose f is
# known fell 55-95% and read the same f in each of those ways (rendered walks at 30-110°,
# phone-cc9's 31° and 24° crops; phone-cc9's whole frames, which pin nothing down, 35-40%)
MIN_DEPTH = 0.25
# ... and this share on each side of it, or it lies flat there: cockatoo's curve (a bird
# filling the frame) rose under 0.01% anywhere on its long side and read 18.5°, whose run
# shook 17.3 px against 15.1 at the 69° default. The long side of a narrow lens's curve
# rises slowly, since its x²/f terms are small: 31° and 24° crops of phone-cc9's real
# frames rose 0.1–0.14% two candidates out (0.09% for one encoded once more, which a rule
# asking for the rise there refused) and 0.25–0.39% at 15°; the rendered walks at 30°,
# 45° and 100° rise 9–122% within two candidates, the synthetic crowd at 1° shake 0.13%
MIN_RISE = 0.001
# A deep curve that pins nothing down still rules out a focal length it reads more than
# ``REJECT`` above its minimum, for the nearest it reads within ``ACCEPT`` of it. A
# narrow lens's curve falls steeply from the wide side to about its true f, then lies
# flat on the long side, where its small x²/f terms tell nothing apart: phone-cc9's real
# frames cropped to 50°, 38°, 31° and 26° and encoded at CRF 28 pinned nothing (a rise
# under MIN_RISE) and kept the 69° default, which their curves read 2.9-17% above their
# floors (the 38° crop at CRF 12 too: 3.9%). On a narrow lens the default is the costly
# side: a rendered 30° handheld clip shook 5.16 px given 69°, 3.25 at 45°, 3.00 at its
# true 30° and 3.09 at 15°. phone-cc9's whole frames (69.8°), whose curve also lies flat
# on its long side, read the default 1.05-1.29% above the floor as encoded four ways
# (2.26% at CRF 32), and are kept at it
REJECT = 0.02
# How far into the flat part: the knee itself is the costly side's edge. Within 1% of
# the floor the four crops took 53.4°, 47.0°, 42.3° and 35.8° (f -7%, -20%, -28%, -28%);
# within 0.5%, 47.1°, 41.2°, 36.6° and 31.5° (+7%, -7%, -16%, -18%), and the whole frames
# at CRF 32 46.0° (+58%, where 1% took 55.8°: the cheap side); within 0.25%, 42.6° to
# 28.2° (+19% to -8%), the whole frames at CRF 32 37.4° (+104%)
ACCEPT = 0.005
COARSE = 25  # candidates over the whole range, log-spaced (about 13% apart at 10–150°)
FINE = 9  # candidates from the coarse minimum's one neighbour to the other (odd)
# The coarse grid's cheaper reading of C: every fourth sample (a diagonal pattern, so the
# edges keep theirs), each rotation refitted in two rounds instead of six. On every clip
# whose f is known (rendered walks at 30-110°, phone-cc9's 31° and 24° crops, the 1080p
# bench clip) the coarse minimum, the decision to pin f down and the estimate came out as
# with the exact reading, and likewise with every second or third sample, or one round;
# the GoPro clips still pin nothing down. A candidate's reading fell from 38 to 5 ms of
# CPU (120 pairs of 576 samples)
THIN = 4
COARSE_ROUNDS = 2
REFIT_ROUNDS = 6  # the fine grid's, as the estimator's own refinement (rotation.refine)


@dataclass(frozen=True)
class FocalEstimate:
    """The focal length that best explains the pairs' flow, in pixels at the flow's size,
    or None where the flow does not pin it down; with the cost curve it came from."""

    focal: float | None
    focals: NDArray[np.float64]
    costs: NDArray[np.float64]
    pairs: int

    @property
    def depth(self) -> float:
        """How far the curve rises above its minimum, as a share of its highest point."""
        top = float(self.costs.max()) if len(self.costs) else 0.0
        return float(1.0 - self.costs.min() / top) if top > 0 else 0.0

    def rules_out(self, focal: float) -> bool:
        """Whether the curve reads ``focal`` more than ``REJECT`` above its minimum, and
        is deep enough (``MIN_DEPTH``) for that to mean something."""
        if len(self.costs) < 2 or self.depth < MIN_DEPTH:
            return False
        return bool(self.reading(focal) > (1.0 + REJECT) * self.costs.min())

    def reading(self, focal: float | NDArray) -> float | NDArray:
        """The curve's cost at ``focal`` (px, or an array of them), linear in log f
        between its candidates."""
        return np.interp(np.log(focal), np.log(self.focals), self.costs)

    def nearest_accepted(self, focal: float) -> float:
        """The focal length nearest ``focal`` (in log f) that the curve reads within
        ``ACCEPT`` of its minimum, linearly between its candidates (``focal`` itself
        where it does).

        >>> f = np.geomspace(100.0, 1000.0, 5)  # a floor from 316 px on
        >>> curve = FocalEstimate(None, f, np.array([3.0, 2.0, 1.0, 1.0, 1.0]), 40)
        >>> curve.rules_out(150.0), round(curve.nearest_accepted(150.0), 1)
        (True, 315.5)
        >>> curve.rules_out(700.0), curve.nearest_accepted(700.0)
        (False, 700.0)
        """
        top = (1.0 + ACCEPT) * self.costs.min()
        if self.reading(focal) <= top:
            return float(focal)
        grid = np.geomspace(self.focals[0], self.focals[-1], 2001)
        accepted = grid[self.reading(grid) <= top]
        return float(accepted[np.argmin(np.abs(np.log(accepted / focal)))])


@njit(cache=True, nogil=True)
def residual_fields(x, y, U, V, VALID, W0, f0, f, rounds=REFIT_ROUNDS) -> np.ndarray:
    """d_t(i) = q_t(i) - π(R_t (x_i, y_i, f)) for every pair (P, M, 2), each R_t refitted
    at f from the rotation vector W0[t] found at f0, in ``rounds`` rounds of reweighting."""
    P, M = U.shape
    out = np.zeros((P, M, 2))
    for p in range(P):
        w = np.array([W0[p, 0] * f0 / f, W0[p, 1] * f0 / f, W0[p, 2]])
        R = refine(x, y, x + U[p], y + V[p], f, rodrigues(w), VALID[p], GATE_PX, rounds)
        for i in range(M):
            X0, X1, X2 = rotate_ray(R, x[i], y[i], f)
            if VALID[p, i] and X2 > 1e-9:
                out[p, i, 0] = x[i] + U[p, i] - f * X0 / X2
                out[p, i, 1] = y[i] + V[p, i] - f * X1 / X2
    return out


def cost(x, y, u, v, valid, rotvecs, f0: float, f: float, rounds: int = REFIT_ROUNDS) -> float:
    """C(f) of the module docstring, each rotation refitted in ``rounds`` rounds."""
    d = residual_fields(x, y, u, v, valid, rotvecs, f0, f, rounds)
    return _truncated_sum(d, running_median(d, valid), valid)


def _truncated_sum(d: NDArray, slow: NDArray, valid: NDArray) -> float:
    """Σ min(|d - d̄|², c²) over the valid vectors, d̄ = ``slow`` (the running median)."""
    r2 = np.sum((d - slow) ** 2, axis=-1)
    return float(np.sum(np.minimum(r2, CLIP_PX**2) * valid))


def running_median(d: NDArray, valid: NDArray) -> NDArray[np.float64]:
    """Per sample position, the median of its residual over ±WINDOW pairs (valid ones
    only): the walk's slow parallax, untouched by an outlier here and there."""
    return _running_median(d, valid, WINDOW)


@njit(cache=True, nogil=True)
def _running_median(d, valid, window) -> np.ndarray:
    """The windowed median at every ``STRIDE``-th pair, held for the pairs around it:
    the parallax changes slowly, and a median at every pair would cost 5× as much. Each
    point's series is copied out contiguous and each window insertion-sorted (at most
    31 values): 40% faster than ``np.median`` on the strided values, the same medians."""
    P, M, _ = d.shape
    out = np.zeros_like(d)
    series = np.empty((2, P))
    ok = np.empty(P, np.bool_)
    buf = np.empty(2 * window + 1)
    for i in range(M):
        for q in range(P):
            ok[q] = valid[q, i]
            series[0, q], series[1, q] = d[q, i, 0], d[q, i, 1]
        for centre in range(STRIDE // 2, P + STRIDE // 2, STRIDE):
            p = min(centre, P - 1)
            lo, hi = max(0, p - window), min(P, p + window + 1)
            first, last = max(0, centre - STRIDE // 2), min(P, centre - STRIDE // 2 + STRIDE)
            for c in range(2):
                n = 0
                for q in range(lo, hi):
                    if ok[q]:
                        _insert(buf, n, series[c, q])
                        n += 1
                if n:
                    h = n >> 1
                    value = buf[h] if n & 1 else (buf[h - 1] + buf[h]) / 2
                    out[first:last, i, c] = value
    return out


@njit(cache=True, inline="always")
def _insert(buf, n, x) -> None:
    """x into the sorted buf[:n], which becomes buf[:n + 1]."""
    k = n
    while k > 0 and buf[k - 1] > x:
        buf[k] = buf[k - 1]
        k -= 1
    buf[k] = x


def estimate_focal(
    x: NDArray,
    y: NDArray,
    u: NDArray,
    v: NDArray,
    valid: NDArray,
    rotvecs: NDArray,
    f0: float,
    bounds: tuple[float, float],
) -> FocalEstimate:
    """The focal length (px) best explaining consecutive sampled pairs: positions ``x``,
    ``y`` (M,) relative to the principal point, flows ``u``, ``v`` (P, M) and their
    validity, the rotation vectors found at ``f0`` (P, 3), searched within ``bounds``.
    The estimate's curve is the coarse grid's (its cheaper reading of C)."""
    args = (
        np.asarray(x, np.float64),
        np.asarray(y, np.float64),
        np.ascontiguousarray(u, np.float64),
        np.ascontiguousarray(v, np.float64),
        np.ascontiguousarray(valid, np.bool_),
        np.ascontiguousarray(rotvecs, np.float64),
        float(f0),
    )
    coarse = np.exp(np.linspace(math.log(bounds[0]), math.log(bounds[1]), COARSE))
    coarse_costs = _costs(thinned(args, THIN), coarse, COARSE_ROUNDS)
    k = int(np.argmin(coarse_costs))
    curve = FocalEstimate(None, coarse, coarse_costs, len(u))
    if len(u) < 3 or k in (0, COARSE - 1) or curve.depth < MIN_DEPTH or not _sharp(coarse_costs, k):
        return curve
    fine = np.exp(np.linspace(math.log(coarse[k - 1]), math.log(coarse[k + 1]), FINE))
    fine_costs, j = _descend(lambda ks: _costs(args, fine[ks], REFIT_ROUNDS), FINE)
    j = min(max(j, 1), FINE - 2)
    return replace(curve, focal=_vertex(np.log(fine[j - 1 : j + 2]), fine_costs[j - 1 : j + 2]))


def thinned(args: tuple, every: int) -> tuple:
    """The search's arguments (x, y, u, v, valid, rotvecs, f0) with every ``every``-th
    sample of the grid kept, on diagonals ((row + column) % every == 0): each row and
    column keeps its share, the frame's edges theirs."""
    x, y, u, v, valid, rotvecs, f0 = args
    column = np.unique(x, return_inverse=True)[1]
    row = np.unique(y, return_inverse=True)[1]
    keep = (column + row) % every == 0
    pick = (lambda a: np.ascontiguousarray(a[:, keep])) if every > 1 else (lambda a: a)
    return x[keep], y[keep], pick(u), pick(v), pick(valid), rotvecs, f0


def _descend(costs_of, n: int) -> tuple[NDArray[np.float64], int]:
    """The costs along a grid of n candidates (inf where not read), read downhill from
    the middle (it and its neighbours first, then one at a time) until a point lower
    than both its neighbours, or an end; and that point. The same minimum as reading the
    whole grid wherever it has only one (on the clips measured, 3-5 readings instead of
    9; the 24° crop of phone-cc9 has two, below).
    """
    out = np.full(n, np.inf)

    def read(ks: list[int]) -> None:
        ks = [k for k in ks if 0 <= k < n and np.isinf(out[k])]
        if ks:
            out[ks] = costs_of(np.array(ks))

    j = n // 2
    read([j - 1, j, j + 1])
    while True:
        low = min((k for k in (j - 1, j, j + 1) if 0 <= k < n), key=lambda k: out[k])
        step, j = low - j, low
        if step == 0 or j in (0, n - 1):
            break
        read([j + step])
    return out, j


def _sharp(costs: NDArray, k: int) -> bool:
    """Whether the coarse curve rises ``MIN_RISE`` above its interior minimum at k
    somewhere on each side: a minimum, not a floor the cost lies flat on."""
    rise = min(costs[:k].max(), costs[k + 1 :].max())
    return bool(rise >= (1.0 + MIN_RISE) * costs[k])


def _costs(args: tuple, focals: NDArray, rounds: int) -> NDArray[np.float64]:
    """C(f) (:func:`cost`) for each candidate, on every core (the kernels release the
    GIL): a candidate per thread where there are as many, else each candidate split
    between the threads, its pairs' refits, then its sample positions' running medians.
    The same sums either way. A lone read of the 1080p clip's 120 pairs takes 27 ms
    split, against 38 on one thread; the coarse grid's 25 cheap reads, a thread apiece,
    took 76 ms, and 107 split (each split read has its own overhead)."""
    threads = max(1, get_num_threads())
    with ThreadPoolExecutor(threads) as pool:
        if len(focals) >= threads:
            return np.array(list(pool.map(lambda f: cost(*args, f, rounds), focals)))
        return np.array([_split_cost(pool, threads, args, f, rounds) for f in focals])


def _split_cost(pool, threads: int, args: tuple, f: float, rounds: int) -> float:
    """:func:`cost` with its pairs, then its sample positions, split between threads."""
    x, y, u, v, valid, rotvecs, f0 = args
    pairs = [slice(a, b) for a, b in _bounds(len(u), threads)]
    points = [slice(a, b) for a, b in _bounds(len(x), threads)]

    def fields(part: slice) -> NDArray:
        return residual_fields(x, y, u[part], v[part], valid[part], rotvecs[part], f0, f, rounds)

    d = np.concatenate(list(pool.map(fields, pairs)))

    def medians(part: slice) -> NDArray:
        d_at, valid_at = (np.ascontiguousarray(a[:, part]) for a in (d, valid))
        return running_median(d_at, valid_at)

    return _truncated_sum(d, np.concatenate(list(pool.map(medians, points)), axis=1), valid)


def _bounds(n: int, parts: int) -> list[tuple[int, int]]:
    """[a, b) of ``parts`` near-equal runs of n items (none empty)."""
    edges = np.linspace(0, n, min(parts, max(n, 1)) + 1).round().astype(int)
    return list(itertools.pairwise(edges))


def _vertex(t: NDArray, c: NDArray) -> float:
    """exp of the vertex of the parabola through three (log f, cost) points."""
    (t0, t1, t2), (c0, c1, c2) = t, c
    denom = (t0 - t1) * (t0 - t2) * (t1 - t2)
    a = (t2 * (c1 - c0) + t1 * (c0 - c2) + t0 * (c2 - c1)) / denom
    b = (t2 * t2 * (c0 - c1) + t1 * t1 * (c2 - c0) + t0 * t0 * (c1 - c2)) / denom
    vertex = -b / (2 * a) if a > 0 else t1
    return float(math.exp(min(max(vertex, t0), t2)))
