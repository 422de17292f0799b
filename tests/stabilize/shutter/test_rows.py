"""The visual per-row turns: the gyro mode's, when both see the same rates."""

import numpy as np

from rotation import so3
from stabilize.gyro.integrate import attitude
from stabilize.gyro.log import GyroLog
from stabilize.gyro.rolling_shutter import frame_rotations, row_turns
from stabilize.shutter.readout import readout_for
from stabilize.shutter.rows import visual_rolling_shutter
from stabilize.synth.trajectory import angular_velocity
from tests.stabilize.shutter.helpers import banded_track

HEIGHT = 540


def test_the_row_turns_agree_with_the_gyro_modes_given_the_same_rates():
    readout = 0.025
    track, motion = banded_track(readout, noise_deg=0.0, seed=8)
    _, spline = readout_for(1000 * readout, track)
    R, rolling = visual_rolling_shutter(spline, track.times, readout, HEIGHT)
    # The gyro mode, fed the path's own rates at 1 kHz.
    at = np.arange(track.times[0] - 0.05, track.times[-1] + 0.1, 1e-3)
    gyro = attitude(GyroLog(at, angular_velocity(motion, at)))
    expected = row_turns(gyro, track.times, 0.0, readout, HEIGHT)
    off = np.degrees(so3.angle(rolling.turns @ np.swapaxes(expected.turns, -1, -2)))
    size = np.degrees(so3.angle(expected.turns))
    # The first and last frames' outer rows lie beyond what any band saw.
    assert np.median(off) < 0.05 * np.median(size) and off[2:-2].max() < 0.03
    mid = frame_rotations(gyro, track.times, 0.0, readout)
    assert np.degrees(so3.angle(R @ np.swapaxes(mid, -1, -2)))[2:-2].max() < 0.03


def test_noise_in_the_bands_leaves_the_row_turns_close():
    readout = 0.03
    track, motion = banded_track(readout, noise_deg=0.05, seed=9)
    found, spline = readout_for("auto", track)
    _, rolling = visual_rolling_shutter(spline, track.times, found.seconds, HEIGHT)
    at = np.arange(track.times[0] - 0.05, track.times[-1] + 0.1, 1e-3)
    gyro = attitude(GyroLog(at, angular_velocity(motion, at)))
    expected = row_turns(gyro, track.times, 0.0, readout, HEIGHT)
    off = np.degrees(so3.angle(rolling.turns @ np.swapaxes(expected.turns, -1, -2)))
    assert np.median(off) < 0.2 * np.median(np.degrees(so3.angle(expected.turns)))
