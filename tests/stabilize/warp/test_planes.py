"""I420 frames: splitting, and warps that agree with warping the RGB frame."""

import cv2
import numpy as np

from rotation import so3
from rotation.camera import intrinsics
from stabilize.video import i420
from stabilize.warp.frames import warp_frame
from stabilize.warp.homography import homography
from stabilize.warp.planes import remap_planes, warp_planes
from stabilize.warp.sources import rolling_source
from tests.stabilize.helpers import from_rgb


def texture(h=120, w=160) -> np.ndarray:
    rng = np.random.default_rng(0)
    img = cv2.resize(rng.integers(0, 255, (h // 8, w // 8, 3), np.uint8), (w, h))
    return cv2.GaussianBlur(img, (0, 0), 2.0)


def test_split_and_join_round_trip():
    frame = from_rgb(texture())
    y, u, v = i420.split(frame)
    assert y.shape == (120, 160) and u.shape == v.shape == (60, 80)
    np.testing.assert_array_equal(i420.join(y, u, v), frame)
    assert i420.supports((120, 160)) and not i420.supports((121, 160))


def test_the_i420_warp_is_the_rgb_warp():
    rgb = texture()
    H = homography(intrinsics(150.0, (120, 160)), so3.exp_so3([0.02, -0.03, 0.05]), 1.1)
    via_yuv = warp_planes(from_rgb(rgb), H)
    via_rgb = from_rgb(warp_frame(rgb, H))
    inner = (slice(10, -10), slice(10, -10))
    # Luma: the same pixels; chroma: the same up to where 4:2:0 averages.
    y1, u1, v1 = i420.split(via_yuv)
    y2, u2, v2 = i420.split(via_rgb)
    assert np.abs(y1[inner].astype(int) - y2[inner]).mean() < 0.6
    for a, b in ((u1, u2), (v1, v2)):
        assert np.abs(a[5:-5, 5:-5].astype(int) - b[5:-5, 5:-5]).mean() < 1.0
    # The generic map (rolling shutter, lens) warps the planes the same way.
    rows = np.linspace(-0.5, 119.5, 5)
    mapped = remap_planes(from_rgb(rgb), rolling_source(np.repeat(H[None], 5, 0), rows))
    assert np.abs(mapped.astype(int) - via_yuv).mean() < 0.3


def test_borders_are_black():
    frame = from_rgb(np.full((40, 60, 3), 200, np.uint8))
    shifted = warp_planes(frame, np.array([[1.0, 0, 20], [0, 1, 0], [0, 0, 1]]))
    rgb = i420.to_rgb(shifted)
    assert rgb[:, :10].max() < 20 and rgb[:, 30:].min() > 150
