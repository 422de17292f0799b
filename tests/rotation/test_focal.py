"""The focal length from rotational flow, with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotation import HoughEstimator
from rotation.camera import focal_from_fov
from rotation.focal import estimate_focal
from rotation.synthetic import make_set

SIZE = (270, 480)
BOUNDS = (focal_from_fov(150, 480), focal_from_fov(15, 480))


def estimate(name: str, fov: float, n: int = 90):
    truth = focal_from_fov(fov, SIZE[1])
    data = make_set(name, n, seed=2, focal=truth, max_deg=1.0)
    start = focal_from_fov(69.0, SIZE[1])
    est = HoughEstimator(SIZE, start, max_deg=15)
    u, v, valid = est.samples(data.flows)
    rotvecs = np.array([r.rotvec for r in est.estimate_samples(u, v, valid)])
    return truth, estimate_focal(est.grid.x, est.grid.y, u, v, valid, rotvecs, start, BOUNDS)


@pytest.mark.parametrize("fov", [30.0, 100.0])
def test_the_focal_length_of_pure_rotation_is_recovered(fov):
    truth, found = estimate("pure", fov)
    assert found.focal == pytest.approx(truth, rel=0.005)


@pytest.mark.parametrize("fov", [45.0, 100.0])
def test_a_walk_past_walls_and_people_does_not_steer_it(fov):
    truth, found = estimate("street", fov)
    assert found.focal == pytest.approx(truth, rel=0.03)


def test_no_motion_pins_nothing_down():
    start = focal_from_fov(69.0, SIZE[1])
    est = HoughEstimator(SIZE, start)
    zeros = np.zeros((40, len(est.grid.x)))
    found = estimate_focal(
        est.grid.x, est.grid.y, zeros, zeros, zeros == 0, np.zeros((40, 3)), start, BOUNDS
    )
    assert found.focal is None and math.isclose(found.depth, 0.0, abs_tol=1e-9)


def test_a_curve_flat_on_one_side_pins_nothing_down(monkeypatch):
    """cockatoo (a bird filling the frame): the cost lay flat to 0.001% over the long
    focal lengths, and its minimum there, a hair below the rest, read 18.5°."""
    from rotation import focal as module

    floor = np.r_[np.linspace(2.0, 1.0, 15), np.ones(10)]
    floor[20] -= 1e-6  # the minimum, inside the flat part
    dip = floor + 0.05 * np.abs(np.arange(25) - 20) * (np.arange(25) >= 15)  # a valley
    # a narrow lens's: the long side rises slowly (a 31° crop of phone-cc9's real frames
    # rose 0.01% and 0.09% one and two candidates out, 0.25% at the end)
    narrow = dip.copy()
    narrow[21:] = 1.0 + 4e-4 * np.arange(1, 5)  # 0.08% two out: a floor by that alone
    start = focal_from_fov(69.0, SIZE[1])
    est = HoughEstimator(SIZE, start)
    zeros = np.zeros((40, len(est.grid.x)))
    args = (est.grid.x, est.grid.y, zeros, zeros, zeros == 0, np.zeros((40, 3)), start, BOUNDS)
    for curve, pinned in ((floor, False), (dip, True), (narrow, True)):

        def costs(_args, focals, rounds, coarse=curve):  # the fine grid's: a bowl
            return coarse if len(focals) == module.COARSE else np.log(focals / 200.0) ** 2

        monkeypatch.setattr(module, "_costs", costs)
        assert (estimate_focal(*args).focal is not None) is pinned


def test_a_deep_floor_rules_out_what_it_reads_above_it():
    """A narrow lens's curve: deep, falling from the wide side to a floor it keeps over
    the long focal lengths, so it pins none. A start it reads over REJECT above its
    floor is ruled out, for the nearest it reads within ACCEPT of it; a start on the
    floor or just above is kept; a shallow curve (a subject filling the frame) rules out
    nothing."""
    from rotation.focal import ACCEPT, REJECT, FocalEstimate

    focals = np.geomspace(200.0, 3200.0, 25)  # 800 among them
    costs = np.maximum(1.0, 1.0 + 2.0 * np.log(800.0 / focals))  # the floor from 800 px
    curve = FocalEstimate(None, focals, costs, 40)
    knee = 800.0 * math.exp(-ACCEPT / 2)  # where the floor begins to rise by ACCEPT
    assert curve.rules_out(300.0) and not curve.rules_out(1500.0)
    assert curve.nearest_accepted(300.0) == pytest.approx(knee, rel=2e-3)
    assert curve.nearest_accepted(1500.0) == 1500.0
    # between ACCEPT and REJECT above the floor: not ruled out, so kept
    assert not curve.rules_out(800.0 * math.exp(-(ACCEPT + REJECT) / 4))
    shallow = FocalEstimate(None, focals, 1.0 + 0.2 * (costs - 1.0) / costs.max(), 40)
    assert shallow.depth < 0.25 and not shallow.rules_out(300.0)


@pytest.mark.parametrize("low", [0, 2, 4, 5, 8])
def test_the_fine_grid_is_walked_down_to_its_minimum(low):
    """Downhill from the middle, reading a few candidates: the whole grid's minimum
    wherever it has one, its end where the curve falls all the way."""
    from rotation.focal import _descend

    curve = (np.arange(9) - low) ** 2.0
    read = []

    def costs_of(ks):
        read.extend(ks)
        return curve[ks]

    costs, j = _descend(costs_of, 9)
    assert j == low and costs[j] == 0.0
    assert len(read) == len(set(read)) < 9 or low in (0, 8)
    assert all(np.isfinite(costs[max(j - 1, 0) : j + 2]))


def test_the_coarse_grid_reads_a_third_of_the_samples_to_the_frame_edges():
    from rotation.focal import THIN, thinned

    est = HoughEstimator(SIZE, focal_from_fov(69.0, SIZE[1]))
    x, y = est.grid.x, est.grid.y
    u = np.arange(3 * len(x), dtype=float).reshape(3, -1)
    tx, ty, tu, *_ = thinned((x, y, u, u, u > 0, np.zeros((3, 3)), 1.0), THIN)
    assert len(tx) == pytest.approx(len(x) / THIN, abs=1)
    assert (tx.min(), tx.max(), ty.min(), ty.max()) == (x.min(), x.max(), y.min(), y.max())
    for column in np.unique(x):  # each column keeps its share of the rows
        assert (tx == column).sum() == pytest.approx((x == column).sum() / THIN, abs=1)
    kept = np.isin(x + 1j * y, tx + 1j * ty)  # each kept sample's flow comes with it
    assert np.array_equal(tu, u[:, kept])


def test_a_candidate_split_between_threads_costs_what_it_costs_whole(monkeypatch):
    """The fine grid's reads split each candidate's pairs, then its sample positions,
    between the threads: the same sum as the one-thread reading, to the bit."""
    from rotation import focal as module

    start = focal_from_fov(69.0, SIZE[1])
    est = HoughEstimator(SIZE, start, max_deg=15)
    data = make_set("street", 40, seed=3, focal=focal_from_fov(45.0, SIZE[1]), max_deg=1.0)
    u, v, valid = est.samples(data.flows)
    rotvecs = np.array([r.rotvec for r in est.estimate_samples(u, v, valid)])
    args = (est.grid.x, est.grid.y, u, v, valid, rotvecs, start)
    focals = np.array([0.8, 1.3]) * start
    whole = [module.cost(*args, f) for f in focals]
    for threads in (2, 3):  # a split into as many parts, read one candidate at a time
        monkeypatch.setattr(module, "get_num_threads", lambda t=threads: t)
        split = [module._costs(args, focals[k : k + 1], module.REFIT_ROUNDS)[0] for k in (0, 1)]
        assert split == whole
