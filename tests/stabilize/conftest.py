"""Fixtures of the stabiliser's tests: a short rendered shaky clip, made once."""

from pathlib import Path

import pytest

from stabilize.synth import SynthOptions, render_clip


def render(folder: Path, **options) -> Path:
    """A 2 s, 320×180 rendered clip (with audio) in ``folder``; options of SynthOptions."""
    opts = SynthOptions(size=(180, 320), **{"seconds": 2.0, **options})
    render_clip(folder, opts)
    return folder / "clip.mp4"


@pytest.fixture(scope="session")
def shaky(tmp_path_factory) -> Path:
    return render(tmp_path_factory.mktemp("shaky"), seed=11, shake_deg=1.5, crowd=4)


@pytest.fixture(scope="session")
def fast_walk(tmp_path_factory) -> Path:
    """A rendered 240 fps walk, 1.5 s, with its truth (a global shutter)."""
    return render(
        tmp_path_factory.mktemp("fast"), seconds=1.5, fps=240.0, seed=3, shake_deg=1.5, crowd=4
    )
