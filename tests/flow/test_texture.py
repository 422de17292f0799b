"""flow.texture: where a flow vector can be measured."""

import cv2
import numpy as np

from flow.texture import MIN_TEXTURE, min_eigenvalue, min_eigenvalue_at, textured

ROWS = COLS = np.arange(8, 57, 8)


def test_a_flat_frame_with_sensor_noise_has_nothing_to_measure():
    rng = np.random.default_rng(0)
    noisy = np.clip(128 + rng.normal(0, 1.0, (64, 64)), 0, 255).astype(np.uint8)
    assert not textured(noisy, ROWS, COLS).any()


def test_texture_in_two_directions_is_measured_in_grey_and_in_colour():
    rng = np.random.default_rng(1)
    grey = cv2.GaussianBlur(rng.integers(0, 256, (64, 64)).astype(np.uint8), (5, 5), 1.0)
    colour = np.repeat(grey[..., None], 3, axis=2)
    assert textured(grey, ROWS, COLS).all()
    assert np.array_equal(textured(colour, ROWS, COLS), textured(grey, ROWS, COLS))


def test_a_straight_edge_is_not_measured_but_a_corner_is():
    edge = np.zeros((64, 64), np.uint8)
    edge[:, 32:] = 200  # a vertical edge: its motion along itself is unknown
    corner = np.zeros((64, 64), np.uint8)
    corner[32:, 32:] = 200
    assert min_eigenvalue(edge)[20, 32] < 1e-3 < MIN_TEXTURE < min_eigenvalue(corner)[32, 32]
    assert not textured(edge, np.array([20, 40]), np.array([32])).any()
    assert textured(corner, np.array([32]), np.array([32])).all()


def test_the_measure_is_the_structure_tensors_smaller_eigenvalue_in_grey_levels():
    rng = np.random.default_rng(2)
    grey = cv2.GaussianBlur(rng.integers(0, 256, (48, 64)).astype(np.uint8), (5, 5), 1.5)
    g = grey.astype(np.float64)
    gx = cv2.Sobel(g, cv2.CV_64F, 1, 0, ksize=3) / 8  # grey levels per px
    gy = cv2.Sobel(g, cv2.CV_64F, 0, 1, ksize=3) / 8
    a, b, c = (cv2.blur(p, (7, 7)) for p in (gx * gx, gx * gy, gy * gy))
    expected = 0.5 * (a + c - np.sqrt((a - c) ** 2 + 4 * b * b))
    assert np.allclose(min_eigenvalue(grey), expected, rtol=1e-4, atol=1e-4)


def test_the_measure_at_points_is_the_whole_maps_there():
    rng = np.random.default_rng(3)
    grey = cv2.GaussianBlur(rng.integers(0, 256, (45, 70)).astype(np.uint8), (3, 3), 0.8)
    rows, cols = np.array([0, 1, 2, 17, 42, 43, 44]), np.array([0, 2, 3, 35, 66, 69])
    whole = min_eigenvalue(grey)
    at = min_eigenvalue_at(grey, rows, cols)  # the border too, reflected as OpenCV's
    assert np.allclose(at, whole[np.ix_(rows, cols)], rtol=1e-6, atol=1e-9)
