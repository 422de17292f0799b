"""The residual shake's parts: known motions in, their high-passed RMS out."""

import cv2
import numpy as np
import pytest

from stabilize.evaluate.metrics import evaluate
from stabilize.evaluate.shake import (
    high_passed,
    parts_of,
    principal_spread,
    residual_shake,
    shake_components,
    similarity_motion,
)

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


def similar(points: np.ndarray, dx: float, dy: float, theta: float, scale: float) -> np.ndarray:
    c, s = scale * np.cos(theta), scale * np.sin(theta)
    return points @ np.array([[c, s], [-s, c]]) + [dx, dy]


def test_a_similarity_of_spread_points_is_recovered():
    points = np.random.default_rng(1).uniform([0, 0], [WIDTH, 300], (60, 2)).astype(np.float32)
    moved = similar(points, 3.0, -2.0, 0.01, 1.02).astype(np.float32)
    motion = similarity_motion(points, moved, WIDTH)
    assert motion == pytest.approx([3.0, -2.0, 0.01, np.log(1.02)], abs=1e-3)


def test_points_bunched_together_fix_no_similarity():
    # 13 matches within 22 × 6 px (cockatoo's feathers) fitted a scale of 1e-17: a
    # cluster pins neither the roll nor the scale down
    rng = np.random.default_rng(2)
    cluster = rng.uniform([100, 100], [122, 106], (40, 2)).astype(np.float32)
    moved = similar(cluster, 1.0, 0.0, 0.0, 1.0).astype(np.float32)
    assert similarity_motion(cluster, moved, WIDTH) is None


def test_features_matched_to_one_point_fix_no_similarity():
    # spread features all matched to one feature of the next frame (cockatoo's lens
    # covered, read upside down): the fit sent everything there, a zoom of 1/1000 that
    # alone read 261 px of shake for the clip
    points = np.random.default_rng(4).uniform([0, 0], [WIDTH, 300], (40, 2)).astype(np.float32)
    one = np.tile(np.float32([[200.0, 150.0]]), (40, 1))
    one += np.random.default_rng(5).normal(0, 0.2, one.shape).astype(np.float32)
    assert similarity_motion(points, one, WIDTH) is None
    assert similarity_motion(one, points, WIDTH) is None


def test_a_long_strip_of_points_fixes_a_similarity():
    # along a strip the roll and the scale show; only a homography needs more
    strip = np.random.default_rng(3).uniform([0, 100], [WIDTH, 106], (60, 2)).astype(np.float32)
    moved = similar(strip, -1.0, 2.0, 0.005, 0.99).astype(np.float32)
    assert similarity_motion(strip, moved, WIDTH) == pytest.approx(
        [-1.0, 2.0, 0.005, np.log(0.99)], abs=2e-3
    )
    narrow, wide = principal_spread(strip)
    assert narrow == pytest.approx(6 / np.sqrt(12), rel=0.3)
    assert wide == pytest.approx(WIDTH / np.sqrt(12), rel=0.2)


def _panned(shift_x: np.ndarray) -> list[np.ndarray]:
    """Frames (540, 960) of one textured picture, moved sideways by ``shift_x`` px each:
    a camera whose every motion is known to a fraction of a pixel."""
    rng = np.random.default_rng(7)
    picture = np.zeros((700, 1400), np.float32)
    for size in (3, 9, 27):  # texture at three scales, as a real scene has
        noise = rng.random((700 // size + 2, 1400 // size + 2)).astype(np.float32)
        picture += cv2.resize(noise, (1400, 700), interpolation=cv2.INTER_CUBIC)[:700, :1400]
    picture = cv2.cvtColor(np.uint8(255 * picture / picture.max()), cv2.COLOR_GRAY2RGB)
    frames = []
    for x in shift_x:
        move = np.float32([[1, 0, -150 - x], [0, 1, -80]])
        frames.append(cv2.warpAffine(picture, move, (960, 540), flags=cv2.INTER_LINEAR))
    return frames


@pytest.mark.parametrize(("pan_px", "shake_px"), [(0.93, 0.0), (0.93, 0.3), (0.0, 0.3), (2.5, 0.0)])
def test_the_shake_of_a_known_motion_is_read_to_a_fraction_of_a_pixel(pan_px, shake_px):
    # A steady pan reads no shake, and a shake of a third of a pixel reads as itself, pan
    # or not. With ORB's keypoints alone the pan of 0.93 px a frame read 0.264 px of shake
    # and the shake without a pan 0.034: they sit on each pyramid level's pixel grid
    # (2 s: each case's error, 0.004-0.018 px, within 0.001 px of 3 s's, in 2/3 the time)
    t = np.arange(60) / 30.0
    x = pan_px * np.arange(60) + shake_px * np.sin(2 * np.pi * 3.1 * t)
    truth = residual_shake(
        parts_of(high_passed(np.c_[np.diff(x), np.zeros((59, 3))], 960, 30)), 960
    )
    read = evaluate(_panned(x), 30.0)
    assert read.registration_failures == 0
    assert read.residual_shake_px == pytest.approx(truth[0], abs=0.02)
