from itertools import pairwise

import cv2
import numpy as np
import pytest

from flow.dis import PRESETS, DISFlow
from flow.grain import BLUR_PX, GRAINY, NOISY, blur_for, noise_level, through_grain
from tests.flow.conftest import shifted_pair, texture


def _half_flat(seed: int = 0) -> np.ndarray:
    """A 480×270 grey frame: texture on the left, a smooth ramp (a sky, a wall) on the
    right, as floats."""
    grey = cv2.cvtColor(texture(270, 480, seed), cv2.COLOR_RGB2GRAY).astype(np.float32)
    rows, cols = np.mgrid[0:270, 0:480]
    grey[:, 240:] = (60 + 0.2 * cols + 0.1 * rows)[:, 240:]
    return grey


def _plain_dis(grey0: np.ndarray, grey1: np.ndarray) -> np.ndarray:
    """OpenCV's DIS at our "fast" preset on the frames as they are, with no blur."""
    dis = cv2.DISOpticalFlow_create(PRESETS["fast"][0])
    dis.setFinestScale(PRESETS["fast"][1])
    return dis.calc(grey0, grey1, None)


@pytest.mark.parametrize("sigma", [1.0, 2.0, 4.0])
def test_the_noise_is_read_on_the_flattest_blocks(sigma):
    grey = _half_flat()
    rng = np.random.default_rng(3)
    noisy = np.clip(grey + rng.normal(0, sigma, grey.shape), 0, 255).round().astype(np.uint8)
    # the 10th percentile of the blocks lies a little under their mean: 0.96, 1.82, 3.59
    assert 0.85 * sigma < noise_level(noisy) < 1.1 * sigma
    # the texture alone, and its rounding to grey levels, read far under NOISY
    assert noise_level(grey.round().astype(np.uint8)) < 0.3


def test_the_blur_rises_with_the_noise_from_noisy_to_grainy():
    assert blur_for(0.0) == blur_for(NOISY) == 0.0
    assert blur_for((NOISY + GRAINY) / 2) == pytest.approx(BLUR_PX / 2)
    assert blur_for(GRAINY) == blur_for(10 * GRAINY) == BLUR_PX


def test_a_clean_pair_is_seen_as_it_is():
    frame0, frame1 = (
        cv2.cvtColor(f, cv2.COLOR_RGB2GRAY) for f in shifted_pair(270, 480, 2.3, -1.1)
    )
    seen = through_grain(frame0, frame1, noise_level(frame0), noise_level(frame1))
    assert seen[0] is frame0 and seen[1] is frame1
    np.testing.assert_array_equal(DISFlow()(frame0, frame1), _plain_dis(frame0, frame1))


def test_a_grainy_pair_is_blurred_alike_on_either_path():
    rng = np.random.default_rng(4)
    frames = [
        np.clip(_half_flat() + rng.normal(0, 3.0, (270, 480)), 0, 255).astype(np.uint8)
        for _ in range(3)
    ]
    assert noise_level(frames[0]) > GRAINY
    dis = DISFlow()
    for flow, (a, b) in zip(dis.many(frames), pairwise(frames), strict=True):
        np.testing.assert_array_equal(flow, dis(a, b))
    assert not np.array_equal(dis(frames[0], frames[1]), _plain_dis(frames[0], frames[1]))
