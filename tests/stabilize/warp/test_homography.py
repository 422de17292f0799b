"""Correction homographies: K' C K⁻¹, their inverses, and the cropping ratio they give."""

import numpy as np
import pytest

from rotation import so3
from rotation.camera import intrinsics
from stabilize.warp.homography import cropping_ratio, homography

SIZE = (360, 640)
K = intrinsics(500.0, SIZE)


@pytest.mark.parametrize("zoom", [1.0, 1.15, 1.5])
def test_a_zoom_about_the_middle_crops_to_its_inverse(zoom):
    # with a roll about the optical axis, and with a shift: neither scales the frame
    roll = homography(K, so3.exp_so3(np.array([0.0, 0.0, 0.2])), zoom)
    shift = np.array([[1.0, 0, 12.0], [0, 1.0, -7.0], [0, 0, 1]]) @ homography(K, np.eye(3), zoom)
    assert cropping_ratio(np.stack([roll, shift]), SIZE) == pytest.approx(1 / zoom, rel=1e-12)


def test_it_is_the_inverse_maps_scale_at_the_output_middle():
    rng = np.random.default_rng(4)
    H = np.stack([homography(K, so3.exp_so3(rng.normal(0, 0.08, 3)), 1.2) for _ in range(5)])
    middle, d = np.array([(SIZE[1] - 1) / 2, (SIZE[0] - 1) / 2]), 1e-3
    dx, dy = np.array([d, 0.0]), np.array([0.0, d])

    def source(Hinv, p):
        u = Hinv @ np.r_[p, 1.0]
        return u[:2] / u[2]

    ratios = cropping_ratio(H, SIZE)
    assert np.abs(ratios - 1 / 1.2).max() > 1e-4  # the turns' keystone counts too
    for h, got in zip(H, ratios, strict=True):
        Hinv = np.linalg.inv(h)
        J = np.stack(
            [
                source(Hinv, middle + dx) - source(Hinv, middle - dx),
                source(Hinv, middle + dy) - source(Hinv, middle - dy),
            ],
            axis=1,
        ) / (2 * d)
        assert got == pytest.approx(np.sqrt(abs(np.linalg.det(J))), rel=1e-7)
