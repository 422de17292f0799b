"""Hough voting in a cube of rotation bins.

The cube holds n³ bins of edge ``s`` centred on ω = 0, so ω maps to bin coordinates
g = ω / s + n / 2 and bin (i, j, k) spans [i, i+1) × [j, j+1) × [k, k+1). n is odd so
that ω = 0 is a bin centre.

Like the paper, no list of votes is sorted: each vote increments a flat counter and
the running maximum is tracked as votes arrive. Only the touched counters are reset
afterwards, so a large, mostly empty accumulator costs nothing per field.

Each Longuet-Higgins line votes exactly once for every bin it crosses, found by a
3-D digital differential analyser (Amanatides & Woo 1987), so ``support`` counts the
lines that really pass through the winning bin. Perspective curves are sampled
finely and vote once per bin they enter.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# state: [number of touched bins, best bin, best count]
N_TOUCHED, BEST, BEST_COUNT = 0, 1, 2


@njit(cache=True)
def bins_per_axis(half_range: float, bin_size: float) -> int:
    """Odd n whose central bin is centred on 0 and whose cube covers ±half_range."""
    return 2 * int(math.ceil(half_range / bin_size - 0.5 - 1e-9)) + 1


@njit(cache=True)
def cast(acc: np.ndarray, touched: np.ndarray, state: np.ndarray, idx: int) -> None:
    c = acc[idx] + 1
    acc[idx] = c
    if c == 1:
        touched[state[N_TOUCHED]] = idx
        state[N_TOUCHED] += 1
    if c > state[BEST_COUNT]:
        state[BEST_COUNT] = c
        state[BEST] = idx


@njit(cache=True)
def reset(acc: np.ndarray, touched: np.ndarray, state: np.ndarray) -> None:
    for k in range(state[N_TOUCHED]):
        acc[touched[k]] = 0
    state[:] = 0


@njit(cache=True)
def _clip(t0: float, t1: float, g0: float, d: float, lo: float, hi: float) -> tuple:
    """Narrow [t0, t1] to where g0 + t d lies in [lo, hi) (one slab of the slab test)."""
    if d == 0.0:
        return (t0, t1) if lo <= g0 < hi else (1.0, 0.0)
    ta = (lo - g0) / d
    tb = (hi - g0) / d
    return max(t0, min(ta, tb)), min(t1, max(ta, tb))


@njit(cache=True)
def _walk(g0: float, d: float, i: int) -> tuple:
    """DDA set-up along one axis: (step, t of the next bin face, t per bin)."""
    if d > 0.0:
        return 1, (i + 1 - g0) / d, 1.0 / d
    if d < 0.0:
        return -1, (i - g0) / d, -1.0 / d
    return 0, np.inf, np.inf


@njit(cache=True)
def lh_segment(a0: float, b0: float, da: float, db: float, n: int) -> tuple:
    """Part [t0, t1] inside the cube of the line (a0 + t da, b0 + t db, n/2 + t).

    This is a Longuet-Higgins line in bin coordinates, parametrised by C (in bins),
    which it always crosses since its direction is the viewing ray (x/f, y/f, 1).
    """
    t0, t1 = -0.5 * n, 0.5 * n
    t0, t1 = _clip(t0, t1, a0, da, 0.0, n)
    return _clip(t0, t1, b0, db, 0.0, n)


@njit(cache=True)
def vote_lh_line(
    a0: float,
    b0: float,
    da: float,
    db: float,
    n: int,
    acc: np.ndarray,
    touched: np.ndarray,
    state: np.ndarray,
) -> None:
    """One vote for every bin the line crosses (3-D DDA walk along the segment)."""
    t0, t1 = lh_segment(a0, b0, da, db, n)
    if not t0 < t1:
        return
    # Start just inside the cube, so rounding at its face cannot pick an outside bin.
    t = t0 + 1e-9 * (t1 - t0)
    c0 = 0.5 * n
    i = min(max(int(math.floor(a0 + t * da)), 0), n - 1)
    j = min(max(int(math.floor(b0 + t * db)), 0), n - 1)
    k = min(max(int(math.floor(c0 + t)), 0), n - 1)
    si, ti, dti = _walk(a0, da, i)
    sj, tj, dtj = _walk(b0, db, j)
    tk = k + 1 - c0
    while True:
        # The body of cast(), written out: the call costs 3×, and even numba's
        # inline='always' took a pair from 0.39 to 1.06 ms (bench/rotation_bench.py).
        idx = (i * n + j) * n + k
        c = acc[idx] + 1
        acc[idx] = c
        if c == 1:
            touched[state[N_TOUCHED]] = idx
            state[N_TOUCHED] += 1
        if c > state[BEST_COUNT]:
            state[BEST_COUNT] = c
            state[BEST] = idx
        if ti <= tj and ti <= tk:
            if ti >= t1:
                return
            i += si
            ti += dti
        elif tj <= tk:
            if tj >= t1:
                return
            j += sj
            tj += dtj
        else:
            if tk >= t1:
                return
            k += 1
            tk += 1.0
        if i < 0 or i >= n or j < 0 or j >= n or k >= n:
            return


@njit(cache=True)
def lh_line_hits_bin(a0: float, b0: float, da: float, db: float, n: int, b: np.ndarray) -> bool:
    """Whether the line (a0 + t da, b0 + t db, n/2 + t) passes through the inside of bin b."""
    t0, t1 = b[2] - 0.5 * n, b[2] + 1 - 0.5 * n
    t0, t1 = _clip(t0, t1, a0, da, b[0], b[0] + 1.0)
    t0, t1 = _clip(t0, t1, b0, db, b[1], b[1] + 1.0)
    return t0 < t1


@njit(cache=True)
def unravel(idx: int, n: int) -> np.ndarray:
    out = np.empty(3, np.int64)
    out[2] = idx % n
    out[1] = (idx // n) % n
    out[0] = idx // (n * n)
    return out


@njit(cache=True)
def bin_center(b: np.ndarray, n: int, s: float) -> np.ndarray:
    """ω at the centre of bin b."""
    return (b.astype(np.float64) + 0.5 - 0.5 * n) * s


@njit(cache=True)
def point_bins(points: np.ndarray, n: int, s: float, out: np.ndarray) -> int:
    """Flat bins of a sampled curve, inside the cube, consecutive repeats dropped."""
    count = 0
    last = -1
    for k in range(points.shape[0]):
        inside = True
        flat = 0
        for a in range(3):
            g = points[k, a] / s + 0.5 * n
            if not (0.0 <= g < n):
                inside = False
                break
            flat = flat * n + int(math.floor(g))
        if inside and flat != last:
            out[count] = flat
            count += 1
            last = flat
    return count
