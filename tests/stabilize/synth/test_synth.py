import numpy as np
import pytest

import flow
from rotation import HoughEstimator, so3
from stabilize.synth import SynthOptions, render_frames, trajectory

SMALL = {"size": (180, 320), "seconds": 0.4, "fps": 30.0}


def truth_rotations(opts: SynthOptions) -> np.ndarray:
    return trajectory.relative_rotations(opts.motion, np.arange(opts.n_frames) / opts.fps)


def test_rendered_rotation_agrees_with_the_flow_measured_on_it():
    # Rotate only: no walking, nobody moving, so every pixel's flow is pure rotation.
    opts = SynthOptions(seed=5, walk=0.0, crowd=0, shake_deg=1.5, **SMALL)
    frames, exact = zip(*render_frames(opts, with_flow=True), strict=True)
    R = truth_rotations(opts)
    estimator = HoughEstimator(opts.size, opts.focal)
    exact_err = [so3.angular_error_deg(estimator.estimate(f).matrix, r)
                 for f, r in zip(exact[:-1], R, strict=True)]  # fmt: skip
    assert np.mean(exact_err) < 2e-3  # the renderer's flow and its truth agree exactly
    measured = flow.get("dis", preset="medium").many(frames)
    err = [so3.angular_error_deg(estimator.estimate(f).matrix, r)
           for f, r in zip(measured, R, strict=True)]  # fmt: skip
    assert np.mean(err) < 0.05


def test_ground_truth_flow_follows_walking_people():
    opts = SynthOptions(seed=2, walk=1.5, crowd=6, **SMALL)
    _, flow_gt = next(iter(render_frames(opts, with_flow=True)))
    assert np.isfinite(flow_gt).mean() > 0.99
    with pytest.raises(ValueError, match="global shutter"):
        next(iter(render_frames(SynthOptions(rolling_shutter_ms=20, **SMALL), with_flow=True)))


def test_rendering_is_deterministic_and_seeded():
    a = [f for f, _ in render_frames(SynthOptions(seed=1, **SMALL))]
    b = [f for f, _ in render_frames(SynthOptions(seed=1, **SMALL))]
    c = [f for f, _ in render_frames(SynthOptions(seed=2, **SMALL))]
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not np.array_equal(a[3], c[3])


def test_rolling_shutter_bends_the_frame():
    gs = next(iter(render_frames(SynthOptions(seed=4, shake_deg=3.0, **SMALL))))[0]
    rs = next(iter(render_frames(SynthOptions(seed=4, shake_deg=3.0, rolling_shutter_ms=30,
                                              **SMALL))))[0]  # fmt: skip
    assert np.array_equal(gs[0], rs[0])  # the first row is read at the frame time
    assert not np.array_equal(gs[-1], rs[-1])


def test_a_steady_walk_only_moves_forward():
    steady = SynthOptions(walk=1.4, shake_deg=0.0, pan_deg=0.0, bob_m=0.0, sway_m=0.0, **SMALL)
    t = np.arange(steady.n_frames) / steady.fps
    centre = trajectory.position(steady.motion, t)
    assert np.allclose(centre[:, :2], 0.0)
    assert np.allclose(np.diff(centre[:, 2]), 1.4 / steady.fps)
    assert np.allclose(truth_rotations(steady), np.eye(3))
    walk = trajectory.position(SynthOptions(walk=1.4, **SMALL).motion, t)
    assert np.abs(walk[:, 1]).max() > 0.01  # the default walk bobs (0.02 m)
    assert np.abs(walk[:, 0]).max() > 0.005  # and sways (0.015 m)
