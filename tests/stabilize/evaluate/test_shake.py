"""The residual shake's parts: known motions in, their high-passed RMS out."""

import numpy as np
import pytest

from stabilize.evaluate.shake import residual_shake, shake_components

WIDTH, FPS = 400, 30.0


def alternating(column: int, amplitude: float, n: int = 90) -> np.ndarray:
    """Frame-to-frame motions (n, 4) whose one column flips sign every frame: all shake."""
    motions = np.zeros((n, 4))
    motions[:, column] = amplitude * (-1.0) ** np.arange(n)
    return motions


@pytest.mark.parametrize("column", [0, 1, 2, 3])
def test_each_part_is_the_shake_of_its_own_component(column):
    # 1 px at the frame's side: the rotation and the zoom count the px they move it by
    amplitude = 1.0 if column < 2 else 2.0 / WIDTH
    parts = shake_components(alternating(column, amplitude), WIDTH, FPS)
    assert parts[column] == pytest.approx(1.0, rel=0.02)
    assert np.delete(parts, column) == pytest.approx(0.0, abs=1e-12)


def test_a_steady_drift_has_no_part():
    drift = np.tile([1.5, -0.5, 1e-3, 2e-4], (90, 1))  # a pan, a slow zoom: intended
    assert shake_components(drift, WIDTH, FPS) == pytest.approx(0.0, abs=1e-9)


def test_the_shake_is_the_length_of_its_parts():
    rng = np.random.default_rng(0)
    motions = rng.normal(0, [1.0, 0.5, 2e-3, 1e-3], (120, 4))
    parts = shake_components(motions, WIDTH, FPS, (WIDTH / 2, 150.0))
    px, deg = residual_shake(parts, WIDTH)
    assert px == pytest.approx(float(np.linalg.norm(parts)))
    assert deg == pytest.approx(np.degrees(parts[2] * 2 / WIDTH))
    assert px > parts.max() > 0


def test_too_few_motions_have_no_shake():
    assert np.isnan(shake_components(np.zeros((2, 4)), WIDTH, FPS)).all()
