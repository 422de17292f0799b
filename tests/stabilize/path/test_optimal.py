"""The steadiest path within the crop budget (the quadratic programme)."""

import numpy as np
import pytest
from scipy import sparse
from scipy.optimize import lsq_linear

from rotation import so3
from rotation.camera import intrinsics
from stabilize.path.budget import Trajectory, respect_zoom_budget
from stabilize.path.optimal import (
    HOLD,
    NEAR,
    OWN,
    TRUST,
    _programme,
    _shake_cost,
    conformal_split,
    high_passed_velocity,
    hold_at,
    image_metric,
    optimal_path,
    unrolled,
    windows,
)
from stabilize.path.plan import plan_path
from stabilize.path.smoothing import smooth_orientations
from stabilize.settings import Settings
from stabilize.warp.coverage import CORNERS, Framing
from tests.stabilize.helpers import shake_operator, shaky_path

K = intrinsics(500.0, (360, 640))
SIZE = (360, 640)


def _jitter(S):
    """Std of the output camera's angular acceleration, deg per frame²."""
    steps = so3.log_so3(S[1:] @ np.swapaxes(S[:-1], -1, -2))
    return float(np.std(np.diff(np.degrees(steps), axis=0)))


def _rotations(O):
    return O[1:] @ np.swapaxes(O[:-1], -1, -2)


@pytest.mark.parametrize("motion", ["rotation", "translation", "similarity"])
def test_every_frame_covers_the_output(motion):
    t, O = shaky_path(n=200, shake_deg=2.0, seed=4)
    rng = np.random.default_rng(5)
    residual = np.c_[rng.normal(0, 0.004, (199, 2)), rng.normal(0, 0.002, (199, 2))]
    settings = Settings(max_zoom=1.08, motion=motion)
    planned = plan_path(t, _rotations(O), np.ones(199), K, SIZE, settings, residual=residual)
    assert planned.zoom.max() <= 1.08 + 1e-9
    assert Framing(K, SIZE).covered(planned.corrections(), planned.zoom + 1e-6).all()


def test_under_a_binding_budget_it_is_steadier_than_the_bent_path():
    t, O = shaky_path(n=240, shake_deg=2.0, seed=7)
    framing = Framing(K, SIZE)
    max_zoom = 1.06
    S = smooth_orientations(O, t, 0.5)
    still = np.zeros((len(O), 4))
    raw, target = Trajectory(O, still), Trajectory(S, still)

    def corrections(part, frames):
        return part.turn @ np.swapaxes(O[frames], -1, -2)

    def zoom_of(part, frames):
        return framing.required_zooms(corrections(part, frames), max_zoom * 1.001)

    def sources(part, frames):
        return framing.border_sources(corrections(part, frames), np.full(len(frames), max_zoom))

    everything = np.arange(len(O))
    assert (zoom_of(target, everything) > max_zoom).mean() > 0.3  # the budget binds
    bent, _ = respect_zoom_budget(raw, target, t, zoom_of, max_zoom, 0.5)
    best = optimal_path(target, sources, SIZE, (), CORNERS)
    assert best is not None
    assert framing.covered(corrections(best, everything), np.full(len(O), max_zoom)).all()
    assert _jitter(best.turn) < 0.8 * _jitter(bent.turn)
    # and it keeps less of what a viewer sees as shake: the high-passed velocity
    H = shake_operator(len(O), 3, 15.0)
    shake = [np.linalg.norm(H @ unrolled(p, ()).ravel()) for p in (best, bent)]
    assert shake[0] < 0.8 * shake[1]


def test_the_shake_operator_sees_no_shake_in_a_steady_move_and_all_of_a_jolt():
    n = 60
    line = np.c_[np.linspace(0, 0.1, n), np.zeros(n), np.linspace(0, -0.05, n)]
    H = shake_operator(n, 3, 15.0)
    assert np.abs(H @ line.ravel()).max() < 1e-12  # a constant-velocity pan is no shake
    jolt = line.copy()
    jolt[30:, 1] += 0.01  # one frame's jump of 0.01 rad
    high = (H @ jolt.ravel()).reshape(n - 1, 3)
    assert abs(high[29, 1] - 0.01) < 0.002 and np.abs(high[:, [0, 2]]).max() < 1e-12


def test_where_the_smoothed_path_fits_the_path_is_steadier_within_the_same_crop():
    t, O = shaky_path(n=120, shake_deg=0.3, seed=2)
    planned = plan_path(t, _rotations(O), np.ones(119), K, SIZE, Settings(max_zoom=1.3))
    framing = Framing(K, SIZE)
    S = smooth_orientations(O, t, 0.5)
    need = framing.required_zooms(S @ np.swapaxes(O, -1, -2), 1.3 * 1.001)
    assert need.max() < 1.3  # the smoothed path fits the budget
    assert planned.zoom.max() <= need.max() + 1e-9  # and no more crop is spent than it spends
    assert framing.covered(planned.corrections(), planned.zoom + 1e-6).all()
    H = shake_operator(len(O), 3, 15.0)
    shake = [np.linalg.norm(H @ unrolled(Trajectory(p, np.zeros((120, 4))), ()).ravel())
             for p in (planned.smooth, S)]  # fmt: skip
    assert shake[0] < 0.5 * shake[1]


def test_long_clips_are_solved_in_windows_that_join_smoothly():
    t, O = shaky_path(n=400, shake_deg=2.0, seed=9)
    planned = plan_path(t, _rotations(O), np.ones(399), K, SIZE, Settings(max_zoom=1.06))
    assert Framing(K, SIZE).covered(planned.corrections(), planned.zoom + 1e-6).all()
    steps = np.degrees(so3.angle(_rotations(planned.smooth)))
    raw_steps = np.degrees(so3.angle(_rotations(O)))
    # No jump where windows meet (every 110 frames): the output never turns faster
    # than the raw camera's fastest frame.
    assert steps.max() < raw_steps.max()


@pytest.mark.parametrize("scale", [1.0, 1e5])
def test_the_programme_reaches_the_optimum_of_a_bounded_least_squares(scale):
    """Bounds |δ| ≤ c on a shaky path's deviations make the programme a bounded least
    squares, ‖[H; √η I] δ + [H p0; 0]‖², which BVLS solves exactly. With rows scaled by
    1e5 none is near binding at δ = 0 (NEAR): they must be found from the answers."""
    rng = np.random.default_rng(1)
    n, k, c = 120, 3, 5e-4
    p0 = np.cumsum(rng.normal(0, 1e-3, (n, k)), axis=0)  # rad
    H = shake_operator(n, k, 15.0).toarray()
    stacked = np.vstack([H, np.sqrt(HOLD) * np.eye(n * k)])
    exact = lsq_linear(
        stacked, np.r_[-H @ p0.ravel(), np.zeros(n * k)], (-c, c), method="bvls", tol=1e-14
    ).x
    assert (np.abs(exact) > 0.999 * c).sum() > 100  # the bounds bind
    eye = sparse.eye_array(n * k, format="csr")
    crop = (sparse.vstack([eye, -eye]).tocsr() * scale, np.full(2 * n * k, c * scale))
    assert scale == 1.0 or (crop[1] > NEAR).all()
    found = _programme(crop, np.zeros((n, k)), 0, np.full((n, k), np.inf), _shake_cost(p0, 15.0))
    # Clarabel's tolerances on the rad² objective as it was (1e-7) stopped 1.7% of c off
    assert np.abs(found.ravel() - exact).max() < 1e-3 * c


def test_a_round_steps_no_further_than_the_linearisation_is_trusted():
    """A programme whose rows leave its optimum 5 rad away (a direction the linearised
    corners barely see) steps only TRUST towards it; one within reach is solved whole."""
    n, k = 4, 2
    cost = (sparse.eye_array(n * k, format="csc"), np.full(n * k, -5.0), None)  # optimum δ = 5
    no_rows = (sparse.csr_array((0, n * k)), np.zeros(0))
    ceiling = np.full((n, k), np.inf)
    found = _programme(no_rows, np.zeros((n, k)), 1, ceiling, cost)
    assert np.allclose(found[0], 0.0)  # the held frame
    assert np.allclose(found[1:], TRUST, atol=1e-6)
    near = (sparse.eye_array(n * k, format="csc"), np.full(n * k, -0.5 * TRUST), None)
    assert np.allclose(_programme(no_rows, np.zeros((n, k)), 0, ceiling, near), 0.5 * TRUST)


def test_a_level_component_keeps_one_deviation_over_the_window():
    """The 2-D angle, level in a window weighed by the image's metric, keeps the held
    frames' last deviation (or x0's first) though the shake would have it move."""
    n, k = 30, 7
    p0 = np.zeros((n, k))
    p0[:, 5] = 0.01 * np.sin(np.arange(n))  # a shaking 2-D angle the cost would undo
    x0 = np.zeros((n, k))
    x0[:2, 5] = [0.003, 0.004]  # the held frames'
    ceiling = np.full((n, k), np.inf)
    no_rows = (sparse.csr_array((0, n * k)), np.zeros(0))
    cost = _shake_cost(p0, 3.0)
    free = _programme(no_rows, x0, 2, ceiling, cost)
    assert np.ptp(free[2:, 5]) > 1e-3  # without: it moves
    level = _programme(no_rows, x0, 2, ceiling, cost, (5,))
    assert np.allclose(level[:2], x0[:2]) and np.allclose(level[2:, 5], 0.004, atol=1e-9)
    assert np.allclose(level[:, :5], free[:, :5], atol=1e-7)  # the others as they were
    first = _programme(no_rows, x0, 0, ceiling, cost, (5,))
    assert np.allclose(first[:, 5], 0.003, atol=1e-9)


def test_a_held_target_is_solved():
    """A held target (--lock) has no shake of its own but its rounding (1e-37 rad² on
    phone-cc9): scaled by that, P was 1e34 and Clarabel found no answer, so every held
    path that did not fit was bent. Frames 40–59 must turn 0.01 rad away from it."""
    n, k = 120, 3
    p0 = np.full((n, k), 0.3) + np.random.default_rng(0).normal(0, 1e-18, (n, k))
    need = np.zeros(n * k)
    need[40 * k : 60 * k] = 1e-2
    crop = (-sparse.eye_array(n * k, format="csr"), -need)
    cost = _shake_cost(p0, 15.0)
    found = _programme(crop, np.zeros((n, k)), 0, np.full((n, k), np.inf), cost)
    assert found is not None and (found[40:60] >= 1e-2 - 1e-9).all()
    assert abs(cost[0]).max() < 1e12


def test_the_conformal_split_gives_the_singular_values():
    J = np.random.default_rng(0).normal(size=(50, 2, 2))
    conf, rest = (np.linalg.norm(v, axis=-1) for v in conformal_split(J))
    s = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_allclose(s[:, 0], conf + rest)
    np.testing.assert_allclose(s[:, 1], np.abs(conf - rest))


def _pan_at_the_end(n: int = 120):
    """(times, rotations, residual) of a pan at a clip's end, 1.5° a frame for 25
    frames, whose image motion the 2-D path undoes."""
    t = np.arange(n) / 30.0
    step = np.zeros(n - 1)
    step[-25:] = np.radians(1.5)
    rotations = so3.exp_so3(np.c_[np.zeros(n - 1), step, np.zeros(n - 1)])
    residual = np.zeros((n - 1, 4))
    residual[:, 0] = -np.tan(step)
    return t, rotations, residual


@pytest.mark.parametrize("max_stretch", [100.0, 0.8])
def test_no_frame_is_stretched_beyond_max_stretch(max_stretch):
    """A pan at the clip's end, 1.5° a frame, that the 2-D path undoes (a focal length
    too short makes a turn of a shift, and the image motion it leaves undoes it): the
    smoothed paths lag it, and the turn they leave keystones the last frames."""
    t, rotations, residual = _pan_at_the_end()
    n = len(t)
    settings = Settings(max_stretch=max_stretch, motion="translation")
    planned = plan_path(t, rotations, np.ones(n - 1), K, SIZE, settings, residual=residual)
    framing = Framing(K, SIZE)
    assert planned.planner == "optimal"
    assert framing.covered(planned.corrections(), planned.zoom + 1e-6).all()
    s = np.linalg.svd(
        framing.middle_jacobian(planned.corrections(), planned.zoom), compute_uv=False
    )
    least = (s[:, 1] / s[:, 0]).min()
    if max_stretch == 100.0:
        assert least < 0.985  # unbounded, the keystone reads 0.983
    else:
        assert least >= 0.992 - 1e-4


def test_a_window_solved_without_the_stretch_bound_is_bounded_from_there(monkeypatch):
    """Where a window has no answer within the bound from its target, it is solved
    without, and the bound's rounds run again from that answer, which covers: they keep
    it or stretch no frame further (cockatoo's middle half at --max-zoom 1.3: frames
    213–235 read 0.82–0.84 solved without the bound, and the view 0.946 now)."""
    import stabilize.path.optimal as optimal

    t, rotations, residual = _pan_at_the_end()
    n = len(t)
    solve, calls = optimal._solve_window, []

    def bounded_fails_first(*args, from_start=False, metric=None):
        calls.append((args[-1][1], from_start))
        return None if len(calls) == 1 else solve(*args, from_start=from_start, metric=metric)

    monkeypatch.setattr(optimal, "_solve_window", bounded_fails_first)
    settings = Settings(motion="translation")
    planned = plan_path(t, rotations, np.ones(n - 1), K, SIZE, settings, residual=residual)
    assert calls == [(0.992, False), (0.0, False), (0.992, True)]
    framing = Framing(K, SIZE)
    assert planned.planner == "optimal"
    assert framing.covered(planned.corrections(), planned.zoom + 1e-6).all()
    s = np.linalg.svd(
        framing.middle_jacobian(planned.corrections(), planned.zoom), compute_uv=False
    )
    assert (s[:, 1] / s[:, 0]).min() >= 0.992 - 1e-4  # unbounded, 0.983


def test_violent_shake_at_a_short_focal_length_is_planned_not_bent():
    """6° of shake at 300 px across 640 (a wide view, or a too short f): steps of the
    linearised programme overshoot, and without shorter ones where a round breaks more
    frames than the last (and the stretch bound that keeps the turns in hand) the rounds
    ran out and the path was bent."""
    K_short = intrinsics(300.0, SIZE)
    t, O = shaky_path(n=150, shake_deg=6.0, seed=0)
    rng = np.random.default_rng(0)
    residual = np.c_[rng.normal(0, 0.02, (149, 2)), rng.normal(0, 0.01, (149, 2))]
    settings = Settings(max_zoom=1.15, motion="similarity")
    planned = plan_path(t, _rotations(O), np.ones(149), K_short, SIZE, settings, residual=residual)
    assert planned.planner == "optimal"
    assert Framing(K_short, SIZE).covered(planned.corrections(), planned.zoom + 1e-6).all()


def _handheld(fps: float, seconds: float = 2.0):
    """(times, O): a steady 5°/s pan under a hand's 2–6 Hz shake, sampled at ``fps``."""
    t = np.arange(round(seconds * fps)) / fps
    yaw = 5.0 * t + 0.8 * np.sin(2 * np.pi * 3.1 * t) + 0.5 * np.sin(2 * np.pi * 5.3 * t + 1)
    pitch = 0.6 * np.sin(2 * np.pi * 2.3 * t + 0.5) + 0.3 * np.sin(2 * np.pi * 4.1 * t)
    return t, so3.exp_so3(-np.radians(np.c_[pitch, yaw, np.zeros_like(t)]))


def _shake_per_thirtieth(t, S):
    """The planned path's high-passed velocity, deg a thirtieth of a second (RMS)."""
    every = round(1 / (30 * (t[1] - t[0])))
    steps = unrolled(Trajectory(S[::every], np.zeros((len(S[::every]), 4))), ())
    H = shake_operator(len(steps), 3, 15.0)
    return float(np.degrees(np.sqrt(np.mean((H @ steps.ravel()) ** 2))))


def test_a_high_frame_rate_is_planned_about_as_steadily_a_second_as_30_fps():
    # At 240 fps, windows of 150 frames saw under the smoothing's reach and the hold on
    # the target outweighed the shake 64 times over: the pan lurched where it starts,
    # 0.0082° a thirtieth of a second (0.07 px at f = 500); now 0.0011 (0.01 px), and
    # 0.00013 at 30 fps, where the programme is the one tuned
    shakes = []
    for fps in (30.0, 240.0):
        t, O = _handheld(fps)
        settings = Settings(max_zoom=1.3)
        planned = plan_path(t, _rotations(O), np.ones(len(t) - 1), K, SIZE, settings)
        assert Framing(K, SIZE).covered(planned.corrections(), planned.zoom + 1e-6).all()
        shakes.append(_shake_per_thirtieth(t, planned.smooth))
    assert shakes[0] < 0.0005 and shakes[1] < 0.0025, shakes


def test_windows_see_what_the_smoothing_sees():
    assert windows(15.0) == (150, 40)  # 30 fps, --smooth 0.5: as measured
    frames, overlap = windows(120.0)  # 240 fps
    assert frames >= 2.5 * 120 and overlap >= 120


def test_the_hold_weighs_a_second_as_at_30_fps():
    assert hold_at(1 / 30) == HOLD and hold_at(1 / 20) == HOLD
    assert hold_at(1 / 240) == pytest.approx(HOLD / 64)


def test_the_image_metric_weighs_a_turn_and_a_shift_by_how_they_move_the_frame():
    # f = 500 px, w = 640: a roll moves the side by r = 320/500 of what a pitch moves it.
    r = 320 / 500
    G = image_metric((0, 1, 2, 3), 500.0, 640)
    eps = 1e-3
    together = np.array([0, eps, 0, eps, 0, 0, 0])  # a yaw and a shift both move x by +2ε
    undone = np.array([0, eps, 0, -eps, 0, 0, 0])  # the shift undoes the yaw: x still
    assert together @ G @ together == pytest.approx((4 + 2 * OWN) * eps**2)
    assert undone @ G @ undone == pytest.approx(2 * OWN * eps**2)
    pitch_and_y = np.array([-eps, 0, 0, 0, eps, 0, 0])  # y = -ω_x + t_y
    assert pitch_and_y @ G @ pitch_and_y == pytest.approx((4 + 2 * OWN) * eps**2)
    roll = np.array([0, 0, eps, 0, 0, eps, 0])  # the turn's roll and the 2-D angle add
    assert roll @ G @ roll == pytest.approx((4 + 2 * OWN) * (r * eps) ** 2)
    # the turn alone: each axis as far as it moves the frame
    assert np.allclose(image_metric((), 500.0, 640), np.diag([1, 1, r * r]) * (1 + OWN))


def test_the_image_metrics_programme_is_solved_in_whitened_variables():
    """Under a metric G = LLᵀ the cost BᵀB ⊗ G is solved as BᵀB ⊗ I in y = (I ⊗ Lᵀ) δ;
    the answer, back in δ, is the programme's in δ itself (held frames and crop rows
    included), and it is not the answer with the components alike."""
    n, parts = 40, (0, 1, 2, 3)
    k = 3 + len(parts)
    p0 = np.cumsum(np.random.default_rng(3).normal(0, 0.01, (n, k)), axis=0)
    G = image_metric(parts, 500.0, 640)
    crop = (-sparse.eye_array(n * k, format="csr")[k * 10 : k * 20 : k], -np.full(10, 0.02))
    x0 = np.zeros((n, k))
    x0[0] = 0.001
    ceiling = np.full((n, k), np.inf)
    whitened = _programme(crop, x0, 1, ceiling, _shake_cost(p0, 5.0, metric=G))
    P, q, _ = _shake_cost(p0, 5.0)  # the components alike
    B = high_passed_velocity(n, 5.0)
    unit = 0.5 * float(np.sum((B @ p0 @ G) * (B @ p0)))
    M = np.triu(B.T @ B + HOLD * np.eye(n)) / unit
    direct = (
        sparse.csc_array(sparse.triu(sparse.kron(M + np.triu(M, 1).T, G))),
        (B.T @ (B @ p0 @ G)).ravel() / unit,
        None,
    )
    assert np.allclose(whitened, _programme(crop, x0, 1, ceiling, direct), atol=1e-5)
    assert np.allclose(whitened[0], 0.001) and (whitened[10:20, 0] >= 0.02 - 1e-9).all()
    alike = _programme(crop, x0, 1, ceiling, (P, q, None))
    assert np.abs(whitened - alike).max() > 1e-3


def test_a_window_the_budget_binds_in_is_planned_by_the_images_motion():
    # Violent shake against a tight budget, and a 2-D path whose shift follows the turn
    # (the frame moves by both): planned by the image's metric, the path keeps less of
    # the shake as the image moves it than planned with the components alike, and more
    # as the components alike count it; each is the steadier by its own measure.
    t, O = shaky_path(n=120, shake_deg=3.0, seed=11)
    framing = Framing(K, SIZE)
    max_zoom = 1.1
    steps = so3.log_so3(_rotations(O))
    q = np.zeros((len(O), 4))
    q[1:, 0] = np.cumsum(0.5 * steps[:, 1])  # shifts with half the yaw's steps
    S = smooth_orientations(O, t, 0.5)
    qs = np.c_[np.convolve(q[:, 0], np.ones(15) / 15, "same"), np.zeros((len(O), 3))]
    target = Trajectory(S, qs)

    def sources(part, frames):
        D = np.tile(np.eye(3), (len(frames), 1, 1))
        D[:, 0, 2] = part.shift[:, 0] - q[frames, 0]
        C = D @ part.turn @ np.swapaxes(O[frames], -1, -2)
        return framing.border_sources(C, np.full(len(frames), max_zoom))

    G = image_metric((0,), 500.0, 640)
    alike = optimal_path(target, sources, SIZE, (0,), CORNERS)
    by_image = optimal_path(target, sources, SIZE, (0,), CORNERS, image=G)
    assert alike is not None and by_image is not None
    H = shake_operator(len(O), 4, 15.0)

    def shake(path, metric):
        v = (H @ unrolled(path, (0,)).ravel()).reshape(-1, 4)
        return float(np.einsum("ij,jk,ik->", v, metric, v))

    assert shake(by_image, G) < shake(alike, G)
    assert shake(alike, np.eye(4)) < shake(by_image, np.eye(4))
