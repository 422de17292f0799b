"""Fixtures of the gyro tests: a rendered rolling-shutter clip with its gyro log."""

from pathlib import Path

import pytest

from stabilize.synth import SynthOptions, render_clip


@pytest.fixture(scope="session")
def rolling_clip(tmp_path_factory) -> Path:
    """A 3 s, 480×270 clip read out over 25 ms, with gyro.csv and truth.json beside it."""
    folder = tmp_path_factory.mktemp("rolling")
    opts = SynthOptions(size=(270, 480), seconds=3.0, seed=5, shake_deg=1.5, rolling_shutter_ms=25)
    render_clip(folder, opts)
    return folder
