"""The attitude fit leaves out the bands a moving subject filled."""

from dataclasses import replace

import numpy as np
import pytest

from rotation import so3
from stabilize.shutter.attitude import agrees_with_frame
from stabilize.shutter.readout import estimate_readout, readout_for
from stabilize.shutter.rows import visual_rolling_shutter
from tests.stabilize.shutter.helpers import banded_track

HEIGHT = 540
PAIRS = [40, 41]


def swept(track, degrees: float, bands: slice = slice(1, 5)):
    """The track with the given bands of ``PAIRS`` turned a further ``degrees`` about y:
    a subject close to the lens that filled those rows and swept across them."""
    turned = track.bands.copy()
    sweep = so3.exp_so3([0.0, np.radians(degrees), 0.0])
    for pair in PAIRS:
        turned[bands, pair] = sweep @ turned[bands, pair]
    return replace(track, bands=turned)


def test_every_band_of_a_shaking_rolling_shutter_agrees_with_its_frame():
    track, _ = banded_track(0.03, shake_deg=3.0, noise_deg=0.05, seed=21)
    assert agrees_with_frame(track).all()


def test_the_bands_a_subject_swept_are_left_out_and_the_frames_keep_their_turn():
    readout = 0.025
    track, _ = banded_track(readout, noise_deg=0.05, seed=8)
    hit = swept(track, 4.0)  # four of the six bands of two pairs
    flagged = ~agrees_with_frame(hit)
    assert flagged[1:5][:, PAIRS].all() and flagged.sum() == 8
    rotations = []
    for t in (track, hit):
        _, spline = readout_for(1000 * readout, t)
        rotations.append(visual_rolling_shutter(spline, t.times, readout, HEIGHT)[0])
    off = np.degrees(so3.angle(rotations[1] @ np.swapaxes(rotations[0], -1, -2)))
    assert off.max() < 0.1  # (with the swept bands in the fit: 3.3°)


@pytest.mark.parametrize("degrees", [3.0, -6.0])
def test_a_swept_subject_leaves_the_readout_where_it_was(degrees):
    track, _ = banded_track(0.025, noise_deg=0.05, seed=13)
    found, _ = estimate_readout(swept(track, degrees))
    assert found.seconds == pytest.approx(0.025, abs=5e-4)
