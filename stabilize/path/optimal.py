"""The steadiest path within the crop budget: a linear programme, solved by HiGHS.

The smoothers (:mod:`.smoothing`, :mod:`.residual`) give the path the user asked for,
the target (orientations S⁰_t and 2-D path q⁰_t). Where following it would show a border
at ``max_zoom``, the path must deviate. With the deviation δ_t per frame, about the
target's own camera axes and in the 2-D path's components,

    S_t = exp(δ_t^rot) S⁰_t,     q_t = q⁰_t + δ_t^2d,

and the path p_t = p⁰_t + δ_t (p⁰: the target's turns log(S⁰_{t+1} S⁰_tᵀ) summed, and
its 2-D components), the path is the L1-optimal camera path (Grundmann, Kwatra and Essa,
CVPR 2011), held near the target:

    minimise   Σ_t λ|δ_t|₁ + w₁|Δp_t|₁ + w₂|Δ²p_t|₁ + w₃|Δ³p_t|₁
    subject to every output border point of every frame mapping inside the input.

The crop constraint is linearised around the current δ (a finite-difference Jacobian of
:meth:`stabilize.warp.coverage.Framing.border_sources`, so that lenses and rolling
shutters are handled as the warp handles them), and the programme solved again around
the answer until the exact check passes (a few rounds). Only the output's corners are
constrained at first (for a homography they are enough); border points found outside
are added in later rounds. The 2-D correction may never zoom in (``ceiling``): the zoom
alone spends the crop budget.

Clips are solved in windows of ``WINDOW`` frames that overlap by ``OVERLAP``, the first
frames of each held to the previous window's answer, so time and memory grow linearly
with the clip's length; a window the target fits, with nothing carried into it, is not
solved at all.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.optimize import linprog

from rotation import so3
from stabilize.path.budget import Trajectory

# λ, w₁, w₂, w₃: the weight that keeps to the target (the path the user asked for), and
# those of the path's velocity, acceleration and jerk. On a rendered walk at 45° (the
# budget binding in most frames) Grundmann's (10, 1, 100) with λ = 0.01–1 left 3.56–3.62
# px of residual shake, acceleration-led weights (1, 10, 1) with λ = 0.01–0.3 left
# 3.00–3.10 px, and the bending this replaces 5.40 (vid.stab: 3.05).
WEIGHTS = (0.1, 1.0, 10.0, 1.0)
ROUNDS = 6  # linearise, solve, check
STEP = 1e-4  # finite-difference step of the Jacobian (rad, normalised units)
MARGIN_PX = 0.25  # constraints are kept this far inside the frame (the linearisation)
# Frames per programme, and how many each window shares with the next (1.3 s: more
# than the smoothing sees). HiGHS's time grows faster than the window: 600 frames that
# bind throughout planned in 6.4 s with windows of 600, 2.5 s with windows of 150.
WINDOW = 150
OVERLAP = 40
FIXED = 3  # frames at a window's start held to the previous window's answer

# sources(part, frames): the input pixels (n, M, 2) of the output border's M points at
# max_zoom for the given frames, of a path whose part at those frames is ``part``.
Sources = Callable[[Trajectory, NDArray], NDArray]


def unrolled(target: Trajectory, parts: tuple[int, ...]) -> NDArray[np.float64]:
    """The target as a path in R^k: its orientation's increments in the camera's axes,
    log(S_{t+1} S_tᵀ), summed, and its 2-D components."""
    steps = so3.log_so3(target.turn[1:] @ np.swapaxes(target.turn[:-1], -1, -2))
    turn = np.vstack([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    return np.hstack([turn, target.shift[:, list(parts)]])


def deviate(target: Trajectory, delta: NDArray, parts: tuple[int, ...]) -> Trajectory:
    """The target moved by deviations ``delta`` (n, 3 + len(parts)): turned by
    exp(δ^rot) in its own camera axes, its 2-D path's components moved by δ^2d."""
    turn = so3.exp_so3(delta[:, :3]) @ target.turn
    shift = target.shift.copy()
    shift[:, list(parts)] += delta[:, 3:]
    return Trajectory(turn, shift)


def optimal_path(
    target: Trajectory,
    sources: Sources,
    size: tuple[int, int],
    parts: tuple[int, ...],
    corners: NDArray,
    ceiling: NDArray | None = None,
) -> Trajectory | None:
    """The path nearest ``target`` in the sense above whose every frame covers the
    output; None where the programme fails (the caller falls back). ``corners``: the
    indices, among the border points ``sources`` gives, of the output's corners;
    ``ceiling`` (n, k): upper bounds on δ (+inf for none)."""
    n = len(target.turn)
    k = 3 + len(parts)
    delta = np.zeros((n, k))
    ceiling = np.full((n, k), np.inf) if ceiling is None else ceiling
    start = 0
    while start < n:
        stop = min(n, start + WINDOW)
        fixed = FIXED if start > 0 else 0
        frames = np.arange(start, stop)
        found = _solve_window(
            target, sources, size, parts, corners, frames, delta, fixed, ceiling[frames]
        )
        if found is None:
            return None
        keep = stop if stop == n else stop - OVERLAP + FIXED
        delta[start + fixed : keep] = found[fixed : keep - start]
        if stop == n:
            break
        start = stop - OVERLAP
    return deviate(target, delta, parts)


def _solve_window(
    target: Trajectory,
    sources: Sources,
    size: tuple[int, int],
    parts: tuple[int, ...],
    corners: NDArray,
    frames: NDArray,
    delta: NDArray,
    fixed: int,
    ceiling: NDArray,
) -> NDArray | None:
    """δ (n, k) for one window of ``frames``, its first ``fixed`` rows held, at most
    ``ceiling``."""
    part = target.take(frames)
    x = delta[frames].copy()
    x[fixed:] = 0.0
    h, w = size
    lo, hi = np.array([-0.5, -0.5]), np.array([w - 0.5, h - 0.5])
    on_target = _outside(sources(part, frames), lo, hi)  # (n, M)
    if not x.any() and not on_target.any():
        return x  # the target fits and nothing carries over: no programme to solve
    active = np.zeros(on_target.shape, bool)
    active[fixed:, corners] = True  # the held frames were checked in the last window
    margin = np.full(len(frames), MARGIN_PX)
    for _ in range(ROUNDS):
        src, jac = _linearised(sources, part, frames, x, parts)
        solved = _programme(
            src, jac, x, active, margin, lo, hi, fixed, ceiling, unrolled(part, parts)
        )
        if solved is None:
            return None
        x = solved
        out = _outside(sources(deviate(part, x, parts), frames), lo, hi)
        out[:fixed] = False
        if not out.any():
            return x
        margin[out.any(axis=1)] += 0.5  # the linearisation was off there: further inside
        active |= out
    return None


def _outside(src: NDArray, lo: NDArray, hi: NDArray) -> NDArray[np.bool_]:
    """Which border points (n, M) map outside the input (or nowhere)."""
    with np.errstate(invalid="ignore"):
        inside = ((src >= lo) & (src <= hi)).all(axis=2)
    return ~inside | ~np.isfinite(src).all(axis=2)


def _linearised(
    sources: Sources, part: Trajectory, frames: NDArray, x: NDArray, parts: tuple[int, ...]
) -> tuple[NDArray, NDArray]:
    """The border sources (n, M, 2) at δ = x and their Jacobian (n, M, 2, k)."""
    here = sources(deviate(part, x, parts), frames)
    jac = np.empty((*here.shape, x.shape[1]))
    for j in range(x.shape[1]):
        step = x.copy()
        step[:, j] += STEP
        jac[..., j] = (sources(deviate(part, step, parts), frames) - here) / STEP
    return here, jac


def _programme(
    src: NDArray,
    jac: NDArray,
    x0: NDArray,
    active: NDArray,
    margin: NDArray,
    lo: NDArray,
    hi: NDArray,
    fixed: int,
    ceiling: NDArray,
    p0: NDArray,
) -> NDArray | None:
    """Solve the linear programme around x0 (the target's unrolled path p0); None where
    HiGHS finds no answer."""
    n, k = x0.shape
    nx = n * k
    blocks, rhs = [], []
    # The crop: lo + margin ≤ src + J (x - x0) ≤ hi - margin at the active points.
    f, m = np.nonzero(active & np.isfinite(src).all(axis=2) & np.isfinite(jac).all(axis=(2, 3)))
    for axis in (0, 1):
        J = jac[f, m, axis]  # (c, k)
        base = src[f, m, axis] - np.einsum("ck,ck->c", J, x0[f])
        rows = np.repeat(np.arange(len(f)), k)
        cols = (f[:, None] * k + np.arange(k)).ravel()
        A = sparse.csr_array((J.ravel(), (rows, cols)), shape=(len(f), nx))
        blocks += [A, -A]
        rhs += [hi[axis] - margin[f] - base, base - (lo[axis] + margin[f])]
    crop = sparse.vstack(blocks)
    # The L1 terms: |D δ| ≤ s, for the identity and the three differences.
    operators = [sparse.eye_array(n)]
    for _ in range(3):
        rows = operators[-1].shape[0]
        if rows < 2:
            break
        step = sparse.diags_array([-1.0, 1.0], offsets=[0, 1], shape=(rows - 1, rows))
        operators.append(step @ operators[-1])
    ops = [sparse.kron(D, sparse.eye_array(k)).tocsr() for D in operators]
    weights = WEIGHTS[: len(ops)]
    ns = sum(op.shape[0] for op in ops)
    A_rows = [sparse.hstack([crop, sparse.csr_array((crop.shape[0], ns))])]
    b_rows = [np.concatenate(rhs)]
    offset = 0
    for d, op in enumerate(ops):
        r = op.shape[0]
        pick = sparse.csr_array((np.ones(r), (np.arange(r), offset + np.arange(r))), shape=(r, ns))
        A_rows += [sparse.hstack([op, -pick]), sparse.hstack([-op, -pick])]
        b = op @ p0.ravel() if d > 0 else np.zeros(r)
        b_rows += [-b, b]
        offset += r
    cost = np.concatenate(
        [np.zeros(nx), *[np.full(op.shape[0], wgt) for op, wgt in zip(ops, weights, strict=True)]]
    )
    bounds = np.full((nx + ns, 2), np.nan)
    bounds[:, 0], bounds[:, 1] = -np.inf, np.inf
    bounds[nx:, 0] = 0.0
    bounds[:nx, 1] = np.maximum(ceiling.ravel(), x0.ravel())
    held = x0[:fixed].ravel()
    bounds[: fixed * k, 0] = bounds[: fixed * k, 1] = held
    result = linprog(
        cost,
        A_ub=sparse.vstack(A_rows).tocsc(),
        b_ub=np.concatenate(b_rows),
        bounds=bounds,
        method="highs",
    )
    if result.status != 0:
        return None
    return result.x[:nx].reshape(n, k)
