import pytest

from rotation.camera import (
    default_center,
    focal_from_fov,
    fov_from_focal,
    intrinsics,
    scale_intrinsics,
)


def test_default_principal_point_is_the_middle_pixel_centre():
    assert default_center((270, 480)) == (239.5, 134.5)


def test_scaling_maps_pixel_edges_not_pixel_centres():
    K = intrinsics(800.0, (540, 960), center=(500.0, 260.0))
    K2 = scale_intrinsics(K, 0.5)
    assert K2[0, 0] == 400.0 and K2[1, 1] == 400.0
    # c + 0.5 scales: the left image edge (-0.5) stays the left edge.
    assert K2[0, 2] == pytest.approx((500.0 + 0.5) * 0.5 - 0.5)
    assert K2[1, 2] == pytest.approx((260.0 + 0.5) * 0.5 - 0.5)
    # The default centre of the full frame maps to the default centre of the half frame.
    K3 = scale_intrinsics(intrinsics(800.0, (540, 960)), 0.5)
    assert tuple(K3[:2, 2]) == default_center((270, 480))


def test_anisotropic_scaling():
    K = scale_intrinsics(intrinsics(800.0, (540, 960)), 0.5, 272 / 540)
    assert K[0, 0] == 400.0 and K[1, 1] == pytest.approx(800.0 * 272 / 540)


def test_fov_round_trip():
    f = focal_from_fov(70.0, 1920)
    assert fov_from_focal(f, 1920) == pytest.approx(70.0)
    assert focal_from_fov(90.0, 1000) == pytest.approx(500.0)
