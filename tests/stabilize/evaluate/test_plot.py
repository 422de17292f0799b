"""The evaluation's picture: the series it draws are the ones the figures come from."""

import numpy as np
import pytest

from stabilize.evaluate.metrics import evaluate_pair
from stabilize.evaluate.plot import plot_shake
from stabilize.synth import SynthOptions, render_frames

SMALL = {"size": (180, 320), "seconds": 2.0, "fps": 30.0, "crowd": 0, "seed": 5, "walk": 0}


def test_the_drawn_series_are_what_the_shake_is_the_rms_of(tmp_path):
    frames = [f for f, _ in render_frames(SynthOptions(shake_deg=1.5, **SMALL))]
    original, stabilised = evaluate_pair(frames, frames[:1] * len(frames), fps=30.0)
    series = original.shake_series
    assert series.shape == (len(frames) - 1, 4)
    assert np.sqrt(np.mean(series**2, axis=0)) == pytest.approx(original.shake_components_px)
    assert stabilised.distortion_series.shape == (len(frames),)
    assert "shake_series" not in original.as_dict()
    plot_shake(tmp_path / "shake.png", original, stabilised, 30.0)
    assert (tmp_path / "shake.png").stat().st_size > 20_000
