import math

import pytest

from stabilize import Settings
from stabilize.settings import DEFAULT_FOV


@pytest.mark.parametrize("fov", [None, 90.0])
def test_the_field_of_view_spans_the_long_side_however_the_camera_is_held(fov):
    # A portrait clip's width is its short side: 69° across it would be a camera 1.78×
    # too wide, and so would a phone's quoted 69° given as --fov
    landscape, portrait = (Settings(fov=fov).focal_px(size) for size in ((720, 1280), (1280, 720)))
    half = math.radians(fov or DEFAULT_FOV) / 2
    assert landscape == portrait == pytest.approx(640 / math.tan(half))


def test_a_given_focal_length_wins():
    assert Settings(fov=90.0, focal=500.0).focal_px((1280, 720)) == 500.0
