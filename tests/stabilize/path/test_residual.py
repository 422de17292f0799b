"""The 2-D path: chained, smoothed along lines, undone, never zooming in."""

import numpy as np
import pytest

from stabilize.path.residual import (
    corrections,
    local_line,
    matrices,
    path_of,
    smooth_path,
    step_matrices,
)


def test_the_chain_of_steps_is_the_path_and_its_matrices():
    rng = np.random.default_rng(1)
    steps = rng.normal(0, 0.01, (20, 4))
    q = path_of(steps)
    M = np.eye(3)
    for A in step_matrices(steps):
        M = A @ M
    assert np.allclose(matrices(q)[-1], M)
    assert np.allclose(corrections(q, q), np.eye(3))


def test_a_steady_drift_is_followed_to_the_last_frame():
    # A walk's drift is a line: the local line keeps it, so no crop is spent at the ends.
    t = np.arange(90) / 30.0
    drift = np.c_[0.02 * t, -0.01 * t, np.zeros(90), np.zeros(90)]
    smooth = smooth_path(drift, t, 0.5, "translation")
    assert np.allclose(smooth, drift, atol=1e-12)


def test_shake_is_removed_and_only_the_models_components_move():
    t = np.arange(120) / 30.0
    rng = np.random.default_rng(2)
    q = rng.normal(0, 0.005, (120, 4))
    smooth = smooth_path(q, t, 0.5, "translation")
    assert np.std(np.diff(smooth[:, 0])) < 0.2 * np.std(np.diff(q[:, 0]))
    assert np.array_equal(smooth[:, 2:], q[:, 2:])
    assert np.array_equal(smooth_path(q, t, 0.5, "rotation"), q)
    with pytest.raises(ValueError, match="motion must be one of"):
        smooth_path(q, t, 0.5, "affine")


def test_the_similarity_model_never_zooms_in():
    t = np.arange(120) / 30.0
    q = np.zeros((120, 4))
    q[:, 3] = 0.01 * np.sin(2 * np.pi * 3 * t)  # a walk's zoom bob
    smooth = smooth_path(q, t, 0.5, "similarity")
    assert np.all(smooth[:, 3] - q[:, 3] <= 1e-12)  # D's scale ≤ 1 in every frame
    assert np.std(np.diff(smooth[:, 3])) < 0.2 * np.std(np.diff(q[:, 3]))


def test_local_line_is_exact_on_lines_with_uneven_frame_times():
    t = np.cumsum(np.r_[0.0, np.random.default_rng(3).uniform(0.02, 0.05, 59)])
    values = np.c_[3 * t - 1, -t]
    assert np.allclose(local_line(values, t, 0.3), values)
