"""The steadiest path within the crop budget: a quadratic programme, solved by Clarabel.

The smoothers (:mod:`.smoothing`, :mod:`.residual`) give the path the user asked for,
the target (orientations S⁰_t and 2-D path q⁰_t). Where following it would show a border
at ``max_zoom``, the path must deviate. With the deviation δ_t per frame, about the
target's own camera axes and in the 2-D path's components,

    S_t = exp(δ_t^rot) S⁰_t,     q_t = q⁰_t + δ_t^2d,

and the path p_t = p⁰_t + δ_t (p⁰: the target's turns log(S⁰_{t+1} S⁰_tᵀ) summed, and
its 2-D components), the path is the one whose velocity keeps the least shake,

    minimise   ½ ‖(I - G_σ) Δp‖² + ½ η ‖δ‖²
    subject to every output border point of every frame mapping inside the input,
               and every frame's warp stretching the output's middle no more than
               ``floor`` allows,

where Δp is the frame-to-frame velocity, G_σ a Gaussian low-pass of σ = ``--smooth``
(in frames), so (I - G_σ) Δp is the part of the velocity a viewer sees as shake (the
residual shake of :mod:`stabilize.evaluate.shake`), and η = ``HOLD`` keeps the path
near the target where nothing else decides. A pan is followed because the crop holds
the path within the budget of the raw one.

Where the target breaks the budget in most of a window's frames, the norms weigh the
components by how they move the image (:func:`image_metric`): a turn and a 2-D shift
that move the frame alike are one shake there, as the residual shake reads them. The 2-D
angle, which turns the frame as the turn's roll does, then keeps one deviation over the
window, so that the two cannot drift together.

The crop constraint is linearised around the current δ (a finite-difference Jacobian of
:meth:`stabilize.warp.coverage.Framing.border_sources`, so that lenses and rolling
shutters are handled as the warp handles them), and the programme solved again around
the answer until the exact check passes (a few rounds). Only the output's corners are
constrained at first (for a homography they are enough); border points found outside
are added in later rounds. The 2-D correction may never zoom in (``ceiling``): the zoom
alone spends the crop budget.

The stretch is σ_min/σ_max of the warp's Jacobian at the output's middle
(:meth:`stabilize.warp.coverage.Framing.middle_jacobian`), held at least ``floor``
(1 - ``--max-stretch``): the keystone of a turn about an axis in the image plane, which
the distortion metric reads. Where the focal length is too short (the 69° default on a
view zoomed in) a turn explains a shift with too much of it: on karma's middle third
the path lagged the drone's last turn by 13.7° at 621 px, the 2-D path holding the
middle still, and the last frames read 0.974 (vid.stab 0.997); within the bound, 0.990.

Clips are solved in windows of ``WINDOW`` frames that overlap by ``OVERLAP``, the first
frames of each held to the previous window's answer, so time and memory grow linearly
with the clip's length. Every window is solved, those the target fits too: a smoother
leaves shake that the crop could hold (:func:`stabilize.path.plan.plan_path`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from itertools import product

import numpy as np
from numpy.typing import NDArray
from scipy import sparse

from rotation import so3
from stabilize.path.budget import Trajectory

# η: how strongly the path keeps to the target where the crop leaves it free (rad²
# against the shake's rad²). The L1-optimal path this replaced (Grundmann et al. 2011:
# velocity, acceleration and jerk weighted 1, 10, 1, held by 0.1) left, in px of residual
# shake on karma, max-heromode, the rendered 30° and 45° walks, 0.55, 1.08, 6.44, 3.05;
# this programme, η = 1e-4, 0.51, 0.96, 6.16, 2.98 (η = 1e-3: 0.54, 0.99, 6.17, 2.93;
# vid.stab 0.61, 0.99, 6.86, 3.05). Adding the high-passed velocity to the L1 programme
# as a fifth term helped the GoPro clips and made the 45° walk worse (3.12–3.24).
HOLD = 1e-4
# A window is planned by the image's motion (:func:`image_metric`) where the target breaks
# the budget in at least this share of its frames: violent shake, where the trade between
# the components decides what is left. The rendered 3° and 4° clips of
# bench/path_bench.py break it in 0.55 and 0.77 of their frames, and read 8.07 and 12.48
# px so, against 8.91 and 14.77 (vid.stab 8.62 and 13.13); the real clips of the bench
# break it in at most 0.28 (cockatoo) and plan as before: planned so in every window (the
# 2-D path summed about each frame's middle) they read no steadier (lossless mirrored
# means on 24 views, geometric mean 1.016).
BINDING = 0.5
# In the image's metric, each component's own shake at this share: without it a turn
# undone by an opposite shift costs nothing. Measured with the 2-D path summed about each
# frame's middle: at 0.1 the 3° clip's programme found no answer (bent: 14.11 px), at 0.3
# the 3° and 4° clips read 8.03 and 12.41, at 1.0 8.40 and 13.73
OWN = 0.3
HOLD_FPS = 30.0  # the frame rate HOLD was measured at (:func:`hold_at`)
ROUNDS = 6  # linearise, solve, check
STEP = 1e-4  # finite-difference step of the Jacobian (rad, normalised units)
MARGIN_PX = 0.25  # constraints are kept this far inside the frame (the linearisation)
# Frames per programme, and how many each window shares with the next (1.3 s: more
# than the smoothing sees). HiGHS's time grows faster than the window: 600 frames that
# bind throughout planned in 6.4 s with windows of 600, 2.5 s with windows of 150.
WINDOW = 150
OVERLAP = 40
# ... in σ of the smoothing where that is more (a high frame rate, a long --smooth)
WINDOW_SIGMAS = 2.5
OVERLAP_SIGMAS = 1.0
FIXED = 3  # frames at a window's start held to the previous window's answer
# A programme starts with the rows this close to binding at its linearisation point (px
# of the crop; the ceilings' own units), and takes in any its answer breaks by more than
# BROKEN: with 10 px, the 1080p clip's windows needed 1–2 solves of about 200 of 2,500
NEAR = 10.0
BROKEN = 1e-7

# sources(part, frames): the input pixels (n, M, 2) of the output border's M points at
# max_zoom for the given frames, of a path whose part at those frames is ``part``.
Sources = Callable[[Trajectory, NDArray], NDArray]
# middle(part, frames): the Jacobian (n, 2, 2) of those frames' warps at the output's
# middle (stabilize.warp.coverage.Framing.middle_jacobian).
Middle = Callable[[Trajectory, NDArray], NDArray]
# The disc |s| ≤ r that bounds the stretch (_stretch_rows) is held by the polygon of
# SIDES sides inside it; its rows are scaled so that one within a half of r of binding
# counts as near (NEAR), so that a frame far from its bound adds no rows to a solve.
SIDES = 8
STRETCH_SLACK = 1e-4  # how far under the floor an answer's stretch may read
SHORTER = (0.5, 0.25, 0.125)  # the shares of a step tried where it broke more frames
# The longest step a round takes in any component (rad, normalised units). The rounds
# measured on the real views step at most 0.59; on max-heromode's middle third without
# its readout a round stepped 0.76 to a path over the stretch bound (σ ratio 0.845), the
# next 1,400 along a direction the linearised corners barely see, and its end read
# 3.48 px at distortion 0.843 (within the trust, 1.66 px and 0.993; at 0.5, 1.77 px)
TRUST = 1.0
# The least shake the objective's unit is (rad² a frame and component: 0.0003 px of
# high-passed velocity at 600 px). A held target (--lock) has none (2.7e-37 on
# phone-cc9, against 3.9e-11 to 2.5e-8 for the smoothed targets of the bench), and P
# scaled by it (1.9e34) left Clarabel no answer: every held path was bent
STILL = 1e-13


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
    sigma: float = 15.0,
    middle: Middle | None = None,
    floor: float = 0.0,
    settled: Callable[[int], None] = lambda frames: None,
    hold: float = HOLD,
    image: NDArray | None = None,
) -> Trajectory | None:
    """The steadiest path in the sense above whose every frame covers the output; None
    where the programme fails (the caller falls back). ``corners``: the indices, among
    the border points ``sources`` gives, of the output's corners; ``ceiling`` (n, k):
    upper bounds on δ (+inf for none); ``sigma``: the low-pass's σ, in frames;
    ``middle``, ``floor``: each frame's σ_min/σ_max at the output's middle is held at
    least ``floor`` (none for 0 or without ``middle``); ``settled`` hears how many
    frames are planned so far, after each window; ``hold``: η (:func:`hold_at`);
    ``image``: the components' weights by the image's motion (:func:`image_metric`), for
    the windows whose target breaks the budget in at least ``BINDING`` of their frames."""
    n = len(target.turn)
    k = 3 + len(parts)
    delta = np.zeros((n, k))
    ceiling = np.full((n, k), np.inf) if ceiling is None else ceiling
    # without the stretch bound where no path keeps to it and to the crop
    bounds = [(middle, floor)] if middle is not None and floor > 0 else []
    bounds.append((None, 0.0))
    window_frames, overlap = windows(sigma)
    start = 0
    while start < n:
        stop = min(n, start + window_frames)
        fixed = FIXED if start > 0 else 0
        frames = np.arange(start, stop)
        window = (target, sources, size, parts, corners, frames, delta, fixed)
        binds = image is not None and _binds(target, sources, size, frames)
        # where the image's metric finds no answer, the components alike (6° of shake
        # at f = 300 px across 640: bent by the image's, planned alike)
        for metric, bound in product([image, None] if binds else [None], bounds):
            found = _solve_window(*window, ceiling[frames], sigma, hold, bound, metric=metric)
            if found is not None:
                break
        if found is None:
            return None
        if bound is not bounds[0]:
            # Solved without the bound: the bound's rounds again, started from that
            # answer, which covers, so that they keep it or stretch no frame further
            begun = delta.copy()
            begun[frames] = found
            again = (target, sources, size, parts, corners, frames, begun, fixed)
            kept = _solve_window(
                *again, ceiling[frames], sigma, hold, bounds[0], from_start=True, metric=metric
            )
            found = found if kept is None else kept
        keep = stop if stop == n else stop - overlap + FIXED
        delta[start + fixed : keep] = found[fixed : keep - start]
        settled(keep)
        if stop == n:
            break
        start = stop - overlap
    return deviate(target, delta, parts)


def hold_at(interval: float) -> float:
    """η for frames ``interval`` s apart: ``HOLD`` up to 30 fps, where it was measured
    (the bench's clips run at 20–30 fps), and above, ``HOLD``·(30·interval)², which
    weighs a second of path against its shake as at 30 fps (the shake's velocities
    shrink with the interval, and their count grows as the hold's). At 240 fps ``HOLD``
    outweighed the shake 64 times as much as at 30, and the path kept to the smoother's
    bent start: a steady pan, known exactly, came out 0.41 px a thirtieth of a second
    shaky (windows of 10σ), 0.28 with η so (0.18 at 30 fps)."""
    return HOLD * min(1.0, HOLD_FPS * interval) ** 2


def image_metric(parts: tuple[int, ...], focal: float, width: int) -> NDArray[np.float64]:
    """G (k, k): the weights of the path's components (the turn's increments ω in the
    camera's axes, then the 2-D path's ``parts``) by the image's motion, in units of f.

    A turn ω moves the frame's middle by f·(ω_y, -ω_x) and turns it by ω_z, which moves
    its side by (w/2)·ω_z; the 2-D step moves it by f·(t_x, t_y), turns it by θ and
    zooms it by ln s. The residual shake's parts (:mod:`stabilize.evaluate.shake`) are
    those sums, so with r = (w/2)/f

        x = ω_y + t_x,   y = -ω_x + t_y,   roll = r (ω_z + θ),   zoom = r ln s,

    and G = CᵀC + ``OWN``·W², C the map to (x, y, roll, zoom), W each component's own
    (1, or r for a roll, an angle or a zoom). Equal weights (the identity) see a turn
    and a shift that move the frame together as two smaller shakes. The 2-D steps are
    the chained path's (:mod:`stabilize.path.residual`), the image's to first order."""
    r = width / 2.0 / focal
    C = np.array(
        [
            [0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, r, 0.0, 0.0, r, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, r],
        ]
    )
    own = np.array([1.0, 1.0, r, 1.0, 1.0, r, r])
    columns = [0, 1, 2, *(3 + part for part in parts)]
    C, own = C[:, columns], own[columns]
    return C.T @ C + OWN * np.diag(own * own)


def _binds(target: Trajectory, sources: Sources, size: tuple[int, int], frames: NDArray) -> bool:
    """Whether the target breaks the budget in at least ``BINDING`` of ``frames``."""
    out = _outside(sources(target.take(frames), frames), *_input_box(size)).any(axis=1)
    return bool(out.mean() >= BINDING)


def windows(sigma: float) -> tuple[int, int]:
    """(frames per programme, frames each shares with the next) for a low-pass of σ
    ``sigma`` frames: ``WINDOW`` and ``OVERLAP``, or ``WINDOW_SIGMAS`` and
    ``OVERLAP_SIGMAS`` σ where those are more. A window must see enough of what the
    smoothing sees. At 240 fps (σ = 120 frames), given the gyro's exact turns of a
    rendered steady pan, windows of 150 frames overlapping by 60 left 0.50 px of shake
    a thirtieth of a second (the same pan at 30 fps: 0.18); 200 by 80, 0.37; 2.5σ by σ
    (300 by 120), 0.26; 10σ by 8σ/3, 0.28, its programmes 2.5 times as long (6 s of
    240 fps planned in 10 s at 2.5σ, in 38 s at 10σ, in 4.4 s at 150 by 40)."""
    return (
        max(WINDOW, math.ceil(WINDOW_SIGMAS * sigma)),
        max(OVERLAP, math.ceil(OVERLAP_SIGMAS * sigma)),
    )


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
    sigma: float,
    hold: float,
    stretch: tuple[Middle | None, float],
    from_start: bool = False,
    metric: NDArray | None = None,
) -> NDArray | None:
    """δ (n, k) for one window of ``frames``, its first ``fixed`` rows held, at most
    ``ceiling``, within the ``stretch`` (middle, floor) of :func:`optimal_path`; started
    from the target, or with ``from_start`` from ``delta``; ``metric``: the components'
    weights (:func:`image_metric`; alike without)."""
    part = target.take(frames)
    x = delta[frames].copy()
    if not from_start:
        x[fixed:] = 0.0
    lo, hi = _input_box(size)
    check = partial(_checked, sources, part, frames, parts, lo, hi, fixed)
    src, out = check(x)  # (n, M, 2) at δ = x
    active = np.zeros(src.shape[:2], bool)
    active[fixed:, corners] = True  # the held frames were checked in the last window
    margin = np.full(len(frames), MARGIN_PX)
    cost = _shake_cost(unrolled(part, parts), sigma, hold, metric)  # the same every round
    # In the image's metric the 2-D angle turns the frame as the turn's roll does, so the
    # two drifted together where only the hold weighs them: on path_bench's 3° clip by up
    # to 0.94 rad (54°) and back from round to round, where the linearised crop no longer
    # held (six rounds, 1.8 s; held level, three, 0.8 s; hero7 --lock 79 -> 39 s). Read
    # losslessly (four mirrored readings' mean): 3° 7.99 -> 8.05 px at a crop 0.002
    # lighter, 4° 12.61 -> 12.55, hero7 --lock 1.432 -> 1.392, karma --lock 0.559 -> 0.557
    level = (3 + parts.index(2),) if metric is not None and 2 in parts else ()
    middle, floor = stretch
    bounded = middle is not None and floor > 0
    tight = np.ones(len(frames))  # the stretch bound's share, where the linearisation was off
    # the last answer that covers the output: the start, where it does (a bent path)
    answer = None if out.any() else x
    broken = None  # how many frames the last answer left uncovered
    # the warps' Jacobians at the output's middle at δ = x: the check, and the next
    # round's linearisation point
    here = middle(deviate(part, x, parts), frames) if bounded else None
    for _ in range(ROUNDS):
        jac = _jacobian(sources, part, frames, x, parts, src)
        crop = _crop_rows(src, jac, x, active, margin, lo, hi)
        tries = [crop]
        if bounded:
            # The bound as asked, else no frame stretched further than at x (a path far
            # over it, linearised, can leave no answer)
            conf, rest, grad = _stretch_linearised(middle, part, frames, x, parts, here)
            radius = np.linalg.norm(conf, axis=1) * (1 - floor) / (1 + floor) * tight
            grown = np.maximum(radius, np.linalg.norm(rest, axis=1) / np.cos(np.pi / SIDES))
            tries = [
                _stacked(crop, _stretch_rows(rest, grad, x, r, fixed)) for r in (radius, grown)
            ]
        attempts = (_programme(rows, x, fixed, ceiling, cost, level) for rows in tries)
        solved = next((found for found in attempts if found is not None), None)
        if solved is None:
            return answer
        previous, x = x, solved
        src, out = check(x)  # the check, and the next round's linearisation point
        if broken is not None and out.any(axis=1).sum() > broken:
            # More frames broke than last round: the step went beyond where the rows
            # hold, so a shorter one (cockatoo's middle half: 3 frames out, then 17,
            # 19, 24 in six rounds, and the path was bent; with it the window is solved)
            for share in SHORTER:
                step = previous + share * (solved - previous)
                step_src, step_out = check(step)
                if step_out.any(axis=1).sum() < out.any(axis=1).sum():
                    x, src, out = step, step_src, step_out
        broken = out.any(axis=1).sum()
        short = np.zeros(len(frames), bool)
        if bounded:
            here = middle(deviate(part, x, parts), frames)
            short = _ratio(here) < floor - STRETCH_SLACK
            short[:fixed] = False
        if not out.any():
            answer = x
            if not short.any():
                return x
        margin[out.any(axis=1)] += 0.5  # the linearisation was off there: further inside
        active |= out
        tight[short] *= 0.8
    return answer


def _ratio(J: NDArray) -> NDArray[np.float64]:
    """σ_min/σ_max of 2×2 matrices J (n, 2, 2) (:func:`conformal_split`)."""
    conf, rest = (np.linalg.norm(v, axis=-1) for v in conformal_split(J))
    return (conf - rest) / (conf + rest)


def _checked(
    sources: Sources,
    part: Trajectory,
    frames: NDArray,
    parts: tuple[int, ...],
    lo: NDArray,
    hi: NDArray,
    fixed: int,
    x: NDArray,
) -> tuple[NDArray, NDArray]:
    """(the border sources, which of them lie outside, the held frames' not counted)
    of the window's path at δ = x."""
    src = sources(deviate(part, x, parts), frames)
    out = _outside(src, lo, hi)
    out[:fixed] = False
    return src, out


def _input_box(size: tuple[int, int]) -> tuple[NDArray, NDArray]:
    """(lo, hi): the input's extent (x, y) in pixels, its edge pixels' centres inside."""
    h, w = size
    return np.array([-0.5, -0.5]), np.array([w - 0.5, h - 0.5])


def _outside(src: NDArray, lo: NDArray, hi: NDArray) -> NDArray[np.bool_]:
    """Which border points (n, M) map outside the input (or nowhere)."""
    with np.errstate(invalid="ignore"):
        inside = ((src >= lo) & (src <= hi)).all(axis=2)
    return ~inside | ~np.isfinite(src).all(axis=2)


def _jacobian(
    sources: Sources,
    part: Trajectory,
    frames: NDArray,
    x: NDArray,
    parts: tuple[int, ...],
    here: NDArray,
) -> NDArray:
    """The Jacobian (n, ..., k) at δ = x of a per-frame figure (the border sources
    (n, M, 2), the stretch), ``here`` (n, ...) at x."""
    jac = np.empty((*here.shape, x.shape[1]))
    for j in range(x.shape[1]):
        step = x.copy()
        step[:, j] += STEP
        jac[..., j] = (sources(deviate(part, step, parts), frames) - here) / STEP
    return jac


def conformal_split(J: NDArray) -> tuple[NDArray, NDArray]:
    """(c, s) (..., 2) of 2×2 matrices J = [[a, b], [e, d]]: c = ((a + d)/2, (e - b)/2),
    the scaled rotation nearest J, and s = ((a - d)/2, (b + e)/2), the rest. J's singular
    values are |c| ± |s|, so σ_min/σ_max = (|c| - |s|)/(|c| + |s|)."""
    a, b, e, d = J[..., 0, 0], J[..., 0, 1], J[..., 1, 0], J[..., 1, 1]
    return np.stack([a + d, e - b], -1) / 2, np.stack([a - d, b + e], -1) / 2


def _crop_rows(
    src: NDArray,
    jac: NDArray,
    x0: NDArray,
    active: NDArray,
    margin: NDArray,
    lo: NDArray,
    hi: NDArray,
) -> tuple[sparse.csr_array, NDArray]:
    """(A, b) of the linearised crop A δ ≤ b around x0: lo + margin ≤ src + J (δ - x0)
    ≤ hi - margin at the active border points."""
    n, k = x0.shape
    blocks, rhs = [], []
    f, m = np.nonzero(active & np.isfinite(src).all(axis=2) & np.isfinite(jac).all(axis=(2, 3)))
    for axis in (0, 1):
        J = jac[f, m, axis]  # (c, k)
        base = src[f, m, axis] - np.einsum("ck,ck->c", J, x0[f])
        rows = np.repeat(np.arange(len(f)), k)
        cols = (f[:, None] * k + np.arange(k)).ravel()
        A = sparse.csr_array((J.ravel(), (rows, cols)), shape=(len(f), n * k))
        blocks += [A, -A]
        rhs += [hi[axis] - margin[f] - base, base - (lo[axis] + margin[f])]
    return sparse.vstack(blocks).tocsr(), np.concatenate(rhs)


def _stretch_linearised(
    middle: Middle,
    part: Trajectory,
    frames: NDArray,
    x0: NDArray,
    parts: tuple[int, ...],
    here: NDArray,
) -> tuple[NDArray, NDArray, NDArray]:
    """(c, s, G) at δ = x0: the parts (n, 2) of each frame's Jacobian at the output's
    middle there, ``here`` (n, 2, 2) (:func:`conformal_split`), and the Jacobian
    (n, 2, k) of s in δ."""
    conf, rest = conformal_split(here)
    grad = _jacobian(lambda p, f: conformal_split(middle(p, f))[1], part, frames, x0, parts, rest)
    return conf, rest, grad


def _stretch_rows(
    rest: NDArray, grad: NDArray, x0: NDArray, radius: NDArray, fixed: int
) -> tuple[sparse.csr_array, NDArray]:
    """(A, b) of |s| ≤ r (``radius``, n) linearised around x0, for every frame after the
    ``fixed`` ones: u_m · (s + G (δ - x0)) ≤ r cos(π/SIDES) for the SIDES directions u_m
    (:func:`_stretch_linearised`). With r = |c| (1 - floor)/(1 + floor), σ_min/σ_max ≥
    floor (:func:`conformal_split`)."""
    n, k = x0.shape
    angle = 2 * np.pi * np.arange(SIDES) / SIDES
    u = np.stack([np.cos(angle), np.sin(angle)], 1)  # (SIDES, 2)
    f = np.repeat(np.arange(fixed, n), SIDES)
    m = np.tile(np.arange(SIDES), n - fixed)
    # slack within r/2 reads as NEAR (and with no stretch allowed, within 1e-4 / 2)
    scale = (NEAR / (0.5 * np.maximum(radius, STRETCH_SLACK)))[f]
    G = np.einsum("cj,cjk->ck", u[m], grad[f]) * scale[:, None]  # (c, k)
    b = (radius[f] * np.cos(np.pi / SIDES) - np.einsum("cj,cj->c", u[m], rest[f])) * scale
    b += np.einsum("ck,ck->c", G, x0[f])
    rows = np.repeat(np.arange(len(f)), k)
    cols = (f[:, None] * k + np.arange(k)).ravel()
    return sparse.csr_array((G.ravel(), (rows, cols)), shape=(len(f), n * k)), b


def _stacked(*systems: tuple[sparse.csr_array, NDArray]) -> tuple[sparse.csr_array, NDArray]:
    """The rows of several systems (A, b) of A δ ≤ b, as one."""
    return sparse.vstack([A for A, _ in systems]).tocsr(), np.concatenate([b for _, b in systems])


def high_passed_velocity(n: int, sigma: float) -> NDArray[np.float64]:
    """(I - G_σ) Δ, dense (n - 1, n): the high-passed velocity of a path of n frames
    (G_σ a Gaussian of σ frames, ends held)."""
    from scipy.ndimage import gaussian_filter1d

    eye = np.eye(n - 1)
    high = eye - gaussian_filter1d(eye, max(sigma, 1.0), axis=0, mode="nearest")
    B = np.zeros((n - 1, n))
    B[:, 1:] += high  # frame i + 1 of step i
    B[:, :-1] -= high  # less frame i
    return B


# The shake's quadratic cost (:func:`_shake_cost`): (P, q, T), P's upper triangle in
# the variables y of δ = T y (T None: y = δ).
Cost = tuple[sparse.csc_array, NDArray, sparse.csr_array | None]


def _shake_cost(
    p0: NDArray, sigma: float, hold: float = HOLD, metric: NDArray | None = None
) -> Cost | None:
    """(P, q, T) of the objective ½ yᵀP y + qᵀy = (½ ‖(I - G_σ) Δ(p0 + δ)‖² + ½ η ‖δ‖²)
    / c₀ + const in y, δ = T y, for the target's unrolled path p0 (n, k); None for fewer
    than 3 frames.

    c₀ = ½ ‖(I - G_σ) Δp0‖², the target's own shake, is the unit (at least ``STILL`` a
    frame and component: a held target has none). In rad² the objective
    is about 1e-7, where Clarabel's absolute tolerances (1e-8) end the solve early: on
    karma 0.03–0.1% above the optimum, the path up to 0.4 px off it. P is given as its
    upper triangle, the form Clarabel takes, made once for every solve of the window.
    With H = B ⊗ I_k, the operator on the path's n × k values flattened frame-major,
    HᵀH = BᵀB ⊗ I_k: the components do not meet in the cost, so BᵀB is made dense,
    n × n, and spread over them (y = δ, T None). The sparse product HᵀH took 0.40 s a
    window of 300 frames and 7 components (240 fps), this 0.04.

    With a ``metric`` G = LLᵀ (k, k) the norms are ‖·‖_G (:func:`image_metric`) and
    HᵀH = BᵀB ⊗ G, which couples the components. In y = (I_n ⊗ Lᵀ) δ it is BᵀB ⊗ I_k
    again, and a frame's rows of the constraints still meet that frame's values alone:
    a window's solve on the 3° clip of bench/path_bench.py took 0.10–0.20 s so, where
    BᵀB ⊗ G took 0.15–0.29 (the answers alike to 1e-7).
    """
    n, k = p0.shape
    if n < 3:
        return None
    B = high_passed_velocity(n, sigma)
    shake = B @ p0  # (n - 1, k)
    weighed = shake if metric is None else shake @ metric
    unit = max(0.5 * float(np.sum(weighed * shake)), STILL * n * k)
    M = np.triu(B.T @ B + hold * np.eye(n)) / unit
    P = sparse.kron(sparse.csr_array(M), sparse.eye_array(k)).tocsc()
    q = (B.T @ weighed).ravel() / unit
    if metric is None:
        return P, q, None
    inverse = np.linalg.inv(np.linalg.cholesky(metric).T)  # δ_t = L⁻ᵀ y_t
    T = sparse.kron(sparse.eye_array(n), sparse.csr_array(inverse)).tocsr()
    return P, T.T @ q, T


def _programme(
    crop: tuple[sparse.csr_array, NDArray],
    x0: NDArray,
    fixed: int,
    ceiling: NDArray,
    cost: Cost | None,
    level: tuple[int, ...] = (),
) -> NDArray | None:
    """Solve the quadratic programme of objective ``cost`` (:func:`_shake_cost`) around
    x0 under the linearised ``crop`` (A, b); None where Clarabel finds no answer. The
    components ``level`` keep one deviation over the window: the held frames' last, or
    x0's first where none is held.

    The programme is solved on the rows that bind or nearly bind at x0 (``NEAR``), then
    again with every row the answer breaks, until it breaks none: that answer is the
    whole programme's (a row left out is slack there, so its multiplier is 0), but each
    solve sees a tenth of the rows. The rows couple a frame's components, and with all
    of them the factorisation filled in: 1080p, 10 s, 0.52 s a window, 0.13 here.
    """
    if cost is None:
        return x0.copy()
    n, k = x0.shape
    nx = n * k
    upper = np.maximum(ceiling.ravel(), x0.ravel())
    capped = np.flatnonzero(np.isfinite(upper))
    A = sparse.vstack([crop[0], _picking(capped, nx)]).tocsr()
    b = np.concatenate([crop[1], upper[capped]])
    held = np.arange(fixed * k)
    E, e = _level_rows(level, x0, fixed)
    # the held frames: δ = x0 there; the level components: one value
    equal = (sparse.vstack([_picking(held, nx), E]).tocsr(), np.concatenate([x0.ravel()[held], e]))

    def solved(A: sparse.csr_array, b: NDArray) -> NDArray | None:
        rows = np.flatnonzero(b - A @ x0.ravel() < NEAR)
        while True:
            x = _solve(cost, equal, (A[rows], b[rows]))
            if x is None:
                return None
            broken = np.setdiff1d(np.flatnonzero(A @ x - b > BROKEN), rows)
            if not len(broken):
                return x.reshape(n, k)
            rows = np.union1d(rows, broken)

    x = solved(A, b)
    if x is not None and np.abs(x - x0).max() > TRUST:
        # A step this long is beyond what the linearisation describes: within TRUST
        box = sparse.eye_array(nx, format="csr")
        x = solved(
            sparse.vstack([A, box, -box]).tocsr(),
            np.concatenate([b, x0.ravel() + TRUST, TRUST - x0.ravel()]),
        )
    return x


def _level_rows(
    level: tuple[int, ...], x0: NDArray, fixed: int
) -> tuple[sparse.csr_array, NDArray]:
    """(E, e) of E δ = e holding each component of ``level`` at one value over the frames
    after the ``fixed`` ones: δ_t - δ_{t-1} = 0 from the first free frame on, and with
    none held, δ_0 = x0's frame 0."""
    n, k = x0.shape
    t = np.arange(max(fixed, 1), n)
    blocks, values = [sparse.csr_array((0, n * k))], [np.zeros(0)]
    for c in level:
        if fixed == 0:
            blocks.append(_picking(np.array([c]), n * k))
            values.append(x0[:1, c])
        cols = np.ravel(np.c_[t * k + c, (t - 1) * k + c])
        steps = (np.tile([1.0, -1.0], len(t)), (np.repeat(np.arange(len(t)), 2), cols))
        blocks.append(sparse.csr_array(steps, shape=(len(t), n * k)))
        values.append(np.zeros(len(t)))
    return sparse.vstack(blocks).tocsr(), np.concatenate(values)


def _solve(
    cost: Cost,
    equal: tuple[sparse.csr_array, NDArray],
    below: tuple[sparse.csr_array, NDArray],
) -> NDArray | None:
    """argmin of the ``cost`` (:func:`_shake_cost`) over x = T y subject to E x = e and
    A x ≤ b, by Clarabel; None where it finds no answer. ``equal`` (E, e), ``below``
    (A, b)."""
    import clarabel  # loaded with the first programme, not with the planner

    (P, q, T), (E, e), (A, b) = cost, equal, below
    if T is not None:
        E, A = E @ T, A @ T
    cones = [clarabel.NonnegativeConeT(A.shape[0])]
    if E.shape[0]:  # Clarabel's zero cone: equalities
        cones.insert(0, clarabel.ZeroConeT(E.shape[0]))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    # One thread: on a window's KKT system (about 2,000 rows) Clarabel's threaded
    # factorisation took twice as long on 2 cores. Cockatoo 3× zoomed in (22 solves)
    # planned in 7.8 s instead of 14.2, the whole of cockatoo in 2.0 s instead of 3.1; the
    # paths alike to 1e-12 rad, every output the same to the bit (those two, hero7)
    settings.max_threads = 1
    stacked = sparse.vstack([E, A]).tocsc()
    solver = clarabel.DefaultSolver(P, q, stacked, np.concatenate([e, b]), cones, settings)
    solution = solver.solve()
    if solution.status not in (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved):
        return None
    return np.asarray(solution.x) if T is None else T @ np.asarray(solution.x)


def _picking(index: NDArray, size: int) -> sparse.csr_array:
    """The rows of the identity of ``size`` at ``index``: picks those entries of δ."""
    return sparse.csr_array(
        (np.ones(len(index)), (np.arange(len(index)), index)), shape=(len(index), size)
    )
