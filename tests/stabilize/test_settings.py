import math

import pytest

from stabilize import Settings
from stabilize.settings import DEFAULT_FOV


def test_the_default_focal_length_spans_the_long_side_however_the_camera_is_held():
    # A portrait clip is decoded upright: 69° across its width would be a camera 1.78×
    # too wide
    landscape, portrait = Settings().focal_px((720, 1280)), Settings().focal_px((1280, 720))
    assert landscape == portrait == pytest.approx(640 / math.tan(math.radians(DEFAULT_FOV / 2)))


def test_a_given_field_of_view_spans_the_width_and_a_given_focal_length_wins():
    assert Settings(fov=90.0).focal_px((1280, 720)) == pytest.approx(360.0)
    assert Settings(fov=90.0).focal_px((720, 1280)) == pytest.approx(640.0)
    assert Settings(fov=90.0, focal=500.0).focal_px((1280, 720)) == 500.0
