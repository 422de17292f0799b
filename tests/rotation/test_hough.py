import cv2
import numpy as np
import pytest

import rotation
from rotation import HoughEstimator, RotationEstimate, so3
from rotation.camera import intrinsics, scale_intrinsics
from rotation.synthetic import corrupt, make_set, rotation_flow

SIZE = (270, 480)
F = 413.75


@pytest.fixture(scope="module")
def hough() -> HoughEstimator:
    return HoughEstimator(SIZE, F)


def errors(results: list[RotationEstimate], truth: np.ndarray) -> np.ndarray:
    return np.array(
        [so3.angular_error_deg(r.matrix, R) for r, R in zip(results, truth, strict=True)]
    )


def test_result_fields(hough):
    R = so3.exp_so3([0.01, 0.0, 0.0])
    est = hough.estimate(rotation_flow(R, F, SIZE))
    assert est.matrix.shape == (3, 3) and est.matrix.dtype == np.float64
    assert est.inliers.shape == (18, 32) and est.inliers.dtype == bool
    assert est.support == pytest.approx(est.inliers.mean())
    np.testing.assert_allclose(so3.exp_so3(est.rotvec), est.matrix, atol=1e-12)


def test_pure_rotation_is_exact(hough):
    data = make_set("pure", 20, seed=11)
    err = errors(hough.estimate_many(data.flows), data.rotations)
    assert err.max() < 1e-3


@pytest.mark.parametrize("outliers", [0.6, 0.7, 0.8])
def test_robust_to_many_outliers(hough, outliers):
    rng = np.random.default_rng(int(outliers * 10))
    truth = so3.random_rotations(rng, 10, 2.0)
    flows = np.stack([corrupt(rng, rotation_flow(R, F, SIZE), 0.5, outliers) for R in truth])
    results = hough.estimate_many(flows)
    assert errors(results, truth).mean() < 0.03
    # Support counts the vectors that agree: about the share that is not an outlier.
    assert np.mean([r.support for r in results]) < 1.0 - outliers + 0.1


def test_least_squares_breaks_where_hough_does_not(hough):
    rng = np.random.default_rng(3)
    R = so3.random_rotations(rng, 1, 2.0)[0]
    flow = corrupt(rng, rotation_flow(R, F, SIZE), 0.5, 0.6)
    assert so3.angular_error_deg(rotation.baselines.least_squares(flow, F).matrix, R) > 0.1
    assert so3.angular_error_deg(hough.estimate(flow).matrix, R) < 0.05


def test_refinement_beats_bin_centres():
    data = make_set("street", 20, seed=5)
    refined = errors(HoughEstimator(SIZE, F).estimate_many(data.flows), data.rotations)
    centres = HoughEstimator(SIZE, F, refine=False).estimate_many(data.flows)
    centres = errors(centres, data.rotations)
    assert refined.mean() < 0.6 * centres.mean()
    clean = make_set("pure", 10, seed=6)
    assert (
        errors(
            HoughEstimator(SIZE, F, refine=False).estimate_many(clean.flows), clean.rotations
        ).mean()
        > 0.005
    )
    # The bin centre is within half a bin diagonal of the truth; refinement is not bound by it.
    assert errors(HoughEstimator(SIZE, F).estimate_many(clean.flows), clean.rotations).max() < 1e-4


def test_street_and_crowd_accuracy(hough):
    for name, bound in [("street", 0.035), ("crowd", 0.05)]:
        data = make_set(name, 20, seed=21)
        assert errors(hough.estimate_many(data.flows), data.rotations).mean() < bound, name


@pytest.mark.parametrize("model", ["longuet-higgins", "perspective"])
def test_large_rotation_coarse_to_fine(model):
    rng = np.random.default_rng(8)
    truth = so3.random_rotations(rng, 4, 10.0, 10.0)
    estimator = HoughEstimator(SIZE, F, max_deg=15.0, model=model)
    assert len(estimator.levels) == 2
    for R in truth:
        flow = corrupt(rng, rotation_flow(R, F, SIZE), 0.3, 0.3)
        assert so3.angular_error_deg(estimator.estimate(flow).matrix, R) < 0.05


def test_estimate_many_matches_estimate(hough):
    data = make_set("crowd", 6, seed=9)
    many = hough.estimate_many(data.flows)
    for flow, r in zip(data.flows, many, strict=True):
        one = hough.estimate(flow)
        np.testing.assert_allclose(one.matrix, r.matrix, atol=1e-12)
        np.testing.assert_array_equal(one.inliers, r.inliers)


def test_non_finite_vectors_are_ignored(hough):
    R = so3.exp_so3(np.radians([0.5, -1.0, 0.2]))
    flow = rotation_flow(R, F, SIZE)
    flow[::2, :, 0] = np.nan
    flow[1::4, :, 1] = np.inf
    est = hough.estimate(flow)
    assert so3.angular_error_deg(est.matrix, R) < 1e-3
    assert not est.inliers[np.isnan(flow[hough.grid.rows][:, hough.grid.cols, 0])].any()


def test_too_few_valid_vectors_give_identity(hough):
    flow = np.full((*SIZE, 2), np.nan, np.float32)
    est = hough.estimate(flow)
    assert est.support == 0.0 and not est.inliers.any()
    np.testing.assert_array_equal(est.matrix, np.eye(3))
    flow[hough.grid.rows[0], hough.grid.cols[:3]] = 1.0  # three valid vectors only
    assert hough.estimate(flow).support == 0.0


def test_flow_outside_the_search_range_gives_identity_not_an_error():
    R = so3.exp_so3(np.radians([0.0, 9.0, 0.0]))
    est = HoughEstimator(SIZE, F, max_deg=1.0).estimate(rotation_flow(R, F, SIZE))
    assert est.matrix.shape == (3, 3)


@pytest.mark.parametrize(
    "bad",
    [np.zeros((270, 480)), np.zeros((270, 480, 3)), np.zeros((271, 480, 2)), np.zeros((2, 2))],
)
def test_wrong_shape_raises(hough, bad):
    with pytest.raises(ValueError, match="shape"):
        hough.estimate(bad)


def test_wrong_dtype_raises(hough):
    with pytest.raises(ValueError, match="floating"):
        hough.estimate(np.zeros((*SIZE, 2), np.int32))
    with pytest.raises(ValueError, match="shape"):
        hough.estimate_many(np.zeros((*SIZE, 2), np.float32))


@pytest.mark.parametrize(
    "kwargs",
    [{"focal": -1.0}, {"model": "affine"}, {"step": 0}, {"bin_deg": 0.0}, {"size": (270,)}],
)
def test_bad_options_raise(kwargs):
    args = {"size": SIZE, "focal": F, **kwargs}
    with pytest.raises(ValueError):
        HoughEstimator(args.pop("size"), args.pop("focal"), **args)


def test_convenience_function():
    R = so3.exp_so3([0.0, 0.0, 0.01])
    est = rotation.estimate(rotation_flow(R, F, SIZE), F, step=10)
    assert so3.angular_error_deg(est.matrix, R) < 1e-3


def test_off_centre_principal_point():
    center = (260.0, 120.0)
    R = so3.exp_so3(np.radians([0.8, 0.3, -0.5]))
    flow = rotation_flow(R, F, SIZE, center)
    good = HoughEstimator(SIZE, F, center=center).estimate(flow)
    naive = HoughEstimator(SIZE, F).estimate(flow)
    assert so3.angular_error_deg(good.matrix, R) < 1e-3
    assert so3.angular_error_deg(naive.matrix, R) > 0.01


def test_focal_and_principal_point_scale_with_the_flow():
    full = (540, 960)
    K = intrinsics(2 * F, full, center=(500.0, 260.0))
    R = so3.exp_so3(np.radians([0.6, -1.2, 0.4]))
    flow = rotation_flow(R, K[0, 0], full, (K[0, 2], K[1, 2]))
    small = cv2.resize(flow, (480, 270), interpolation=cv2.INTER_AREA) * 0.5
    K2 = scale_intrinsics(K, 0.5)
    est = HoughEstimator(SIZE, K2[0, 0], center=(K2[0, 2], K2[1, 2])).estimate(small)
    assert so3.angular_error_deg(est.matrix, R) < 2e-3
    # Forgetting to rescale the focal length is a gross error.
    wrong = HoughEstimator(SIZE, K[0, 0], center=(K2[0, 2], K2[1, 2])).estimate(small)
    assert so3.angular_error_deg(wrong.matrix, R) > 0.2


def test_any_layout_runs_one_loaded_kernel():
    # warm_up loads the kernel the pipeline runs; samples in either memory layout must
    # reach it as they are, not load a second signature (25–50 ms a process), and give
    # the same rotations
    from rotation.hough import estimate_chunk, warm_up

    warm_up()
    estimator = HoughEstimator((270, 480), 413.75)
    turns = [so3.exp_so3([0.0, 0.004 * k, 0.001]) for k in (1, 2)]
    flows = np.stack([rotation_flow(R, 413.75, (270, 480)) for R in turns])
    u, v, valid = estimator.samples(flows)
    rows = estimator.estimate_samples(np.ascontiguousarray(u), np.ascontiguousarray(v), valid)
    columns = estimator.estimate_samples(np.asfortranarray(u), np.asfortranarray(v), valid)
    assert len(estimate_chunk.signatures) == 1
    for a, b in zip(rows, columns, strict=True):
        np.testing.assert_array_equal(a.matrix, b.matrix)
