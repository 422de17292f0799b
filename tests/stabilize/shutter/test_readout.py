"""The readout from band rotations alone: recovered, refused, or a global shutter."""

from dataclasses import replace

import numpy as np
import pytest

from stabilize.shutter.readout import _without, estimate_readout, readout_for
from tests.stabilize.shutter.helpers import banded_track


@pytest.mark.parametrize("ms", [15.0, 25.0, 33.0])
def test_the_readout_is_recovered_from_the_bands(ms):
    track, _ = banded_track(ms / 1000.0, seed=int(ms))
    found, spline = estimate_readout(track)
    assert found.source == "estimated" and spline is not None
    assert found.seconds == pytest.approx(ms / 1000.0, abs=5e-4)
    assert 0 < found.stderr < 1e-3


def test_a_global_shutter_is_measured_as_none():
    track, _ = banded_track(0.0, seed=3)
    found, spline = estimate_readout(track)
    assert found.seconds == 0.0 and spline is None and found.source == "estimated"
    assert abs(found.estimate) < 1e-3
    assert "global shutter" in found.describe()


def test_smooth_slow_motion_is_refused():
    # A pan with no shake: every band sees the same turn whatever the readout is.
    track, _ = banded_track(0.025, shake_deg=0.0, noise_deg=0.05, seed=4)
    found, spline = estimate_readout(track)
    assert found.source == "refused" and found.seconds == 0.0 and spline is None
    assert "pin" in found.reason


def test_a_readout_the_clips_halves_disagree_on_is_refused():
    # No sensor reads out in 8 ms for half a clip and 30 ms for the other: a fit that
    # finds that follows something else (a subject, a drone's vibration).
    pairs = 90
    readout = np.where(np.arange(pairs) < pairs // 2, 0.008, 0.030)
    track, _ = banded_track(readout, seed=7)
    found, spline = estimate_readout(track)
    assert found.source == "refused" and found.seconds == 0.0 and spline is None
    assert "halves disagree" in found.reason and found.estimate > 0.008
    steady, _ = banded_track(np.full(pairs, 0.030), seed=7)
    assert estimate_readout(steady)[0].seconds == pytest.approx(0.030, abs=1e-3)
    # A half that reads longer than a frame (45 ms at 30 fps: it comes out at the
    # search's 40 ms end) measured no readout, and contradicts none: the 15 ms half
    # stands, and the whole clip's estimate is kept.
    track, _ = banded_track(np.where(np.arange(pairs) < pairs // 2, 0.045, 0.015), seed=7)
    found, spline = estimate_readout(track)
    assert found.source == "estimated" and found.seconds > 0.010 and spline is not None


def test_too_few_textured_bands_are_refused():
    track, _ = banded_track(0.025, seed=5)
    bare = replace(track, band_support=np.zeros_like(track.band_support))
    found, _ = estimate_readout(bare)
    assert found.source == "refused" and "texture" in found.reason


def test_off_and_a_given_readout_are_kept():
    track, _ = banded_track(0.025, seed=6)
    off, none = readout_for("off", track)
    assert (off.seconds, off.source, none) == (0.0, "off", None)
    given, spline = readout_for(20.0, track)
    assert (given.seconds, given.source) == (0.02, "given") and spline is not None
    assert given.summary()["readout_ms"] == pytest.approx(20.0)


def test_a_long_clip_is_searched_on_its_most_shaking_stretch(monkeypatch):
    import stabilize.shutter.readout as readout

    monkeypatch.setattr(readout, "MAX_SEARCH_PAIRS", 40)
    track, _ = banded_track(0.025, seconds=4.0, seed=12)
    found, spline = readout.estimate_readout(track)
    assert found.seconds == pytest.approx(0.025, abs=1e-3)
    assert spline.knots[-1] > track.times[-1]  # the attitude spans the whole clip


def test_the_attitude_is_not_fitted_to_repaired_pairs():
    # two pairs whose every band read a turn of no camera (a black frame, a cut): their
    # turns were repaired, but the attitude followed their bands, and the rows' turns
    # it gives replaced the repair
    from rotation import so3
    from stabilize.shutter.rows import visual_rolling_shutter

    track, _ = banded_track(0.025, seed=25)
    junk = so3.exp_so3(np.radians([2.0, -1.0, 0.0])[None])[0]
    rotations, bands = track.rotations.copy(), track.bands.copy()
    rotations[40:42], bands[:, 40:42] = junk, junk
    bad = replace(track, rotations=rotations, bands=bands)
    repaired = np.zeros(len(rotations), bool)
    repaired[40:42] = True

    def off_deg(pairs: np.ndarray | None) -> np.ndarray:
        readout, spline = readout_for("25", bad, pairs)
        R, _ = visual_rolling_shutter(spline, bad.times, readout.seconds, 1080)
        apart = R[40:42] @ np.swapaxes(track.rotations[40:42], 1, 2)
        return np.degrees(so3.angle(apart))

    assert (off_deg(None) > 2.5).all()  # 2.9 and 3.3 degrees: the junk followed
    assert (off_deg(repaired) < 0.7).all()  # 0.44 and 0.59: bridged by its neighbours


def test_at_240_fps_the_readout_is_searched_on_the_strides(fast_walk):
    # A 240 fps pair turns too little for its bands to date the rows: this global
    # shutter read 1.7 ± 0.1 ms on them, and its walk's output was corrected by it
    from stabilize import Settings
    from stabilize.motion.estimate import READOUT_BANDS
    from stabilize.motion.focal import estimate_motion
    from stabilize.video import probe

    track, _ = estimate_motion(fast_walk, probe(fast_walk), Settings(), bands=READOUT_BANDS)
    assert track.stride_track is not None and track.stride_track.bands is not None
    on_strides, _ = estimate_readout(track)
    on_pairs, _ = estimate_readout(replace(track, stride_track=None))
    assert on_strides.source == "estimated" and on_strides.seconds == 0.0
    assert on_pairs.seconds > 0.001  # what the pairs alone read, and the test can tell
    repaired = np.zeros(len(track.rotations), bool)
    repaired[:16] = True  # the first two strides' pairs: their bands date nothing
    support = _without(track, repaired).stride_track.band_support
    assert (support[:, :2] == 0).all()
    assert (support[:, 2:] == track.stride_track.band_support[:, 2:]).all()
