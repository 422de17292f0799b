"""The path planning pieces: smoothing on SO(3), the zoom budget, warps, repairs."""

import numpy as np
import pytest

from rotation import so3
from rotation.camera import intrinsics
from stabilize.pipeline import Settings, choose_zoom, plan, repair_unreliable
from stabilize.smoothing import (
    orientations_from_rotations,
    respect_zoom_budget,
    smooth_orientations,
)
from stabilize.warping import covers, homography, required_zoom, required_zooms

K = intrinsics(500.0, (360, 640))
SIZE = (360, 640)


def shaky_path(n=120, seed=0, shake_deg=1.0, pan_deg_s=0.0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 30.0
    angles = np.radians(shake_deg) * rng.normal(size=(n, 3))
    angles[:, 1] += np.radians(pan_deg_s) * t
    O = so3.exp_so3(-angles)  # world → camera
    return t, O


def test_orientations_chain_the_rotations():
    R = so3.random_rotations(np.random.default_rng(1), 5, 2.0)
    O = orientations_from_rotations(R)
    np.testing.assert_allclose(O[3] @ O[2].T, R[2], atol=1e-12)
    np.testing.assert_allclose(O[0], np.eye(3))


def test_gaussian_smoothing_removes_shake_and_keeps_a_pan():
    t, O = shaky_path(pan_deg_s=10.0)
    S = smooth_orientations(O, t, 0.5, "gaussian")
    jitter = lambda P: np.degrees(so3.angle(P[1:] @ np.swapaxes(P[:-1], -1, -2))).std()  # noqa: E731
    assert jitter(S) < 0.1 * jitter(O)
    yaw = np.degrees(so3.log_so3(np.swapaxes(S, -1, -2))[:, 1])
    assert yaw[-10] - yaw[10] == pytest.approx(10.0 * (t[-10] - t[10]), rel=0.15)


def test_lock_holds_one_orientation():
    t, O = shaky_path()
    S = smooth_orientations(O, t, method="lock")
    assert np.allclose(S, S[0])


def test_zoom_of_identity_and_of_a_turn():
    assert required_zoom(K, np.eye(3), SIZE) == 1.0
    turn = so3.exp_so3([0.0, np.radians(3.0), 0.0])
    z = required_zoom(K, turn, SIZE)
    assert 1.0 < z < 1.5
    assert covers(K, turn, z + 1e-6, SIZE) and not covers(K, turn, z - 1e-3, SIZE)
    H = homography(K, np.eye(3), 2.0)
    np.testing.assert_allclose(H @ [K[0, 2], K[1, 2], 1.0], [K[0, 2], K[1, 2], 1.0])


@pytest.mark.parametrize("crop", ["auto", "dynamic"])
def test_the_zoom_budget_is_never_broken(crop):
    t, O = shaky_path(shake_deg=2.0)
    R = O[1:] @ np.swapaxes(O[:-1], -1, -2)
    planned = plan(t, R, np.ones(len(R)), K, SIZE, Settings(max_zoom=1.1, crop=crop, smooth=1.0))
    assert planned.zoom.max() <= 1.1 + 1e-9
    C = planned.smooth @ np.swapaxes(planned.raw, -1, -2)
    assert all(covers(K, c, z + 1e-6, SIZE) for c, z in zip(C, planned.zoom, strict=True))


def test_one_jolt_bends_the_path_only_near_it_and_in_few_rounds():
    # A steady 10 s path with one 4° jolt: only the frames within reach of the pull
    # (4σ of it) may change, and the rounds stay well below PULL_ROUNDS.
    t = np.arange(300) / 30.0
    angles = np.zeros((300, 3))
    angles[150, 1] = np.radians(4.0)
    O = so3.exp_so3(angles)
    S = np.repeat(np.eye(3)[None], 300, axis=0)
    searched = []

    def zoom_of(path, frames):
        searched.append(len(frames))
        return required_zooms(K, path @ np.swapaxes(O[frames], -1, -2), SIZE, 1.2)

    bent, zoom = respect_zoom_budget(O, S, t, zoom_of, 1.1, 0.5)
    assert zoom.max() <= 1.1
    assert len(searched) < 200  # 150 here, far below PULL_ROUNDS
    reach = 4 * 0.5 * 0.5 * 30  # 4σ of the pull, in frames
    far = np.abs(np.arange(300) - 150) > reach + 1
    assert np.array_equal(bent[far], S[far]) and not np.allclose(bent[150], S[150])
    assert max(searched[1:-1]) <= 2 * reach + 3  # the rounds search locally (only the
    # first and the last search cover the whole path)


def test_dynamic_zoom_is_smooth_and_never_below_the_need():
    t = np.arange(60) / 30.0
    need = np.ones(60)
    need[30] = 1.3
    z = choose_zoom(need, t, Settings(crop="dynamic", smooth=0.3, max_zoom=1.5))
    assert np.all(z >= need) and z[30] == pytest.approx(1.3)
    assert np.abs(np.diff(z)).max() < 0.05


def test_unreliable_frames_are_repaired_from_their_neighbours():
    rv = np.tile([0.01, 0.0, 0.0], (9, 1))
    rv[4] = [0.0, 0.08, 0.0]  # a spike that few vectors voted for
    support = np.full(9, 0.2)
    support[4] = 0.01
    R, reliable = repair_unreliable(so3.exp_so3(rv), support)
    assert not reliable[4] and reliable.sum() == 8
    np.testing.assert_allclose(so3.log_so3(R[4]), [0.01, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(so3.log_so3(R[0]), rv[0], atol=1e-12)


def test_the_batched_torch_warp_matches_opencv():
    # The CUDA path (kornia), run on the CPU here: the same pixels as cv2.warpPerspective.
    from rotation.camera import intrinsics
    from stabilize.warping import homography, warp_frame, warp_frames_torch

    rng = np.random.default_rng(0)
    K = intrinsics(500.0, (120, 160))
    frames = rng.integers(0, 255, (3, 120, 160, 3), np.uint8)
    Hs = np.stack([homography(K, so3.exp_so3(rng.normal(0, 0.02, 3)), 1.1) for _ in range(3)])
    torch_out = warp_frames_torch(frames, Hs, "cpu")
    cv_out = np.stack([warp_frame(f, H) for f, H in zip(frames, Hs, strict=True)])
    diff = np.abs(torch_out.astype(int) - cv_out)
    assert diff.mean() < 0.05 and diff.max() <= 2


def test_warp_many_gives_the_same_frames_on_every_device():
    import torch

    from stabilize.pipeline import CameraPath, batches

    n = 5
    eye = np.tile(np.eye(3), (n, 1, 1))
    shift = np.tile(np.array([[1.0, 0, 3], [0, 1, -2], [0, 0, 1]]), (n, 1, 1))
    path = CameraPath(
        np.arange(n) / 30, eye[:-1], np.ones(n - 1), eye, eye, np.ones(n), shift, eye[0]
    )
    frames = np.random.default_rng(1).integers(0, 255, (n, 40, 60, 3), np.uint8)
    items = list(enumerate(frames))
    assert [len(b) for b in batches(items, 2)] == [2, 2, 1]
    on_cpu = np.stack(path.warp_many(items, "cpu"))
    np.testing.assert_array_equal(on_cpu[:, 5:-5, 5:-5], frames[:, 7:-3, 2:-8])  # the shift
    if torch.cuda.is_available():
        on_gpu = np.stack(path.warp_many(items, "cuda"))
        assert np.abs(on_gpu.astype(int) - on_cpu).max() <= 2


def test_the_vectorised_zoom_search_finds_the_least_covering_zoom():
    from stabilize.warping import required_zooms

    K = intrinsics(400.0, (180, 320))
    rng = np.random.default_rng(3)
    C = so3.exp_so3(rng.normal(0, 0.03, (20, 3)))
    C[0] = np.eye(3)
    C[1] = so3.exp_so3([0.0, 0.6, 0.0])  # too far for the zoom limit
    zooms = required_zooms(K, C, (180, 320), 1.5)
    assert zooms[0] == 1.0 and np.isinf(zooms[1])
    checked = 0
    for c, z in zip(C[2:], zooms[2:], strict=True):
        if 1.0 < z < np.inf:
            assert covers(K, c, z, (180, 320)) and not covers(K, c, z - 1e-4, (180, 320))
            checked += 1
    assert checked >= 5


def test_a_long_clip_plans_in_memory_that_grows_with_its_length_not_its_square():
    import tracemalloc

    n = 20_000  # 11 minutes at 30 fps: an (N, N) float matrix would take 3.2 GB
    t = np.arange(n) / 30.0
    angles = np.zeros((n, 3))
    angles[::997, 1] = np.radians(4.0)  # a jolt every half minute
    O = so3.exp_so3(angles)
    S = np.repeat(np.eye(3)[None], n, axis=0)

    def zoom_of(path, frames):  # 1 + the correction's angle: a cheap stand-in
        return 1.0 + so3.angle(path @ np.swapaxes(O[frames], -1, -2))

    need = np.ones(n)
    need[::500] = 1.1
    tracemalloc.start()
    try:
        z = choose_zoom(need, t, Settings(crop="dynamic", smooth=0.5, max_zoom=1.5))
        _, zoom = respect_zoom_budget(O, S, t, zoom_of, 1.03, 0.5)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert np.all(z >= need) and zoom.max() <= 1.03
    assert peak < 200e6, f"{peak / 1e6:.0f} MB"
