"""The rolling-shutter correction's stretch budget: known shears in, eased turns out."""

import numpy as np
import pytest

from rotation import so3
from rotation.camera import intrinsics
from stabilize.warp.rolling import (
    RollingShutter,
    centre_slopes,
    stretch,
    within_stretch,
)

HEIGHT, WIDTH, FOCAL = 480, 640, 500.0
K = intrinsics(FOCAL, (HEIGHT, WIDTH))
FLOOR = 0.992  # the default --max-stretch, 0.8%
ROWS = np.linspace(-0.5, HEIGHT - 0.5, 17)


def panning(rates: np.ndarray) -> RollingShutter:
    """Row turns of frames whose rows turn about the y axis by ``rates`` (rad per row)
    from the middle row: a pan during the readout, which shears the frame."""
    angles = rates[:, None] * (ROWS - K[1, 2])[None, :]
    w = np.zeros((*angles.shape, 3))
    w[..., 1] = angles
    return RollingShutter(so3.exp_so3(w), ROWS)


def test_a_pan_during_the_readout_is_a_shear_of_focal_times_the_rate():
    rates = np.array([0.0, 2e-5, -4e-5])
    slopes = centre_slopes(panning(rates), K)
    # D(y)ᵀ turns row y back by rate·(y - c_y): the centre column moves by -f·rate per row
    assert slopes[:, 0] == pytest.approx(-FOCAL * rates, rel=1e-3, abs=1e-9)
    assert slopes[:, 1] == pytest.approx(0.0, abs=1e-4)  # second order only
    assert stretch(np.array([[0.0, 0.0], [0.01, 0.0]])) == pytest.approx([1.0, 0.99], abs=1e-4)


def test_only_the_frames_past_the_budget_are_eased_and_gradually():
    rates = np.zeros(40)
    rates[20] = 6e-5  # a shear of 0.03: stretch 0.970
    before = panning(rates)
    eased, count = within_stretch(before, K, 3, FLOOR)
    after = stretch(centre_slopes(eased, K))
    assert stretch(centre_slopes(before, K))[20] < 0.975
    assert after.min() >= FLOOR - 1e-4  # every frame within the budget
    assert 1 <= count <= 13  # the frame and its ramp, ±6 frames at most
    np.testing.assert_array_equal(eased.turns[:10], before.turns[:10])  # far ones untouched
    strength = np.abs(centre_slopes(eased, K)[:, 0]) / (FOCAL * 6e-5)
    assert np.abs(np.diff(strength[14:27])).max() < 0.5  # ramped, not switched


def test_a_correction_within_the_budget_is_left_alone():
    gentle = panning(np.full(10, 1e-5))  # shear 0.005
    eased, count = within_stretch(gentle, K, 3, FLOOR)
    assert eased is gentle and count == 0
