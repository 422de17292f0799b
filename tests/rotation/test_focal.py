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
        costs = iter([lambda n, c=curve: c, lambda n: 1.1 - 0.1 * np.hanning(n)])
        monkeypatch.setattr(module, "_costs", lambda _args, focals, c=costs: next(c)(len(focals)))
        assert (estimate_focal(*args).focal is not None) is pinned
