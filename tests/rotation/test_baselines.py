import numpy as np
import pytest

from rotation import baselines, so3
from rotation.synthetic import Street, corrupt, rotation_flow, street_flow

SIZE = (270, 480)
F = 413.75


@pytest.fixture(scope="module")
def rotation_truth() -> np.ndarray:
    return so3.exp_so3(np.radians([0.4, -0.9, 0.3]))


def test_least_squares_on_clean_rotation(rotation_truth):
    est = baselines.least_squares(rotation_flow(rotation_truth, F, SIZE), F)
    # The Longuet-Higgins model is first order: close, not exact.
    assert so3.angular_error_deg(est.matrix, rotation_truth) < 0.02
    assert est.support == 1.0


def test_ransac_rejects_outliers(rotation_truth):
    rng = np.random.default_rng(0)
    flow = corrupt(rng, rotation_flow(rotation_truth, F, SIZE), 0.3, 0.4)
    est = baselines.ransac(flow, F, iterations=300, seed=1)
    assert so3.angular_error_deg(est.matrix, rotation_truth) < 0.05
    assert 0.4 < est.support < 0.8


def test_five_point_with_translation(rotation_truth):
    # The essential matrix needs a baseline: give it a strong sideways step.
    flow = street_flow(rotation_truth, np.array([0.3, 0.0, 0.1]), F, SIZE, Street())
    est = baselines.five_point(flow, F)
    assert so3.angular_error_deg(est.matrix, rotation_truth) < 0.1


def test_baselines_share_the_result_type_and_handle_empty_fields():
    flow = np.full((*SIZE, 2), np.nan, np.float32)
    for method in (baselines.least_squares, baselines.ransac, baselines.five_point):
        est = method(flow, F)
        np.testing.assert_array_equal(est.matrix, np.eye(3))
        assert est.support == 0.0 and est.inliers.shape == (18, 32)
