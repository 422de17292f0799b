"""Warping along a planned path: the batched CUDA warp and the per-device dispatch."""

import numpy as np

from rotation import so3
from rotation.camera import intrinsics
from stabilize.warp.camera_path import CameraPath
from stabilize.warp.cuda import warp_frames_torch
from stabilize.warp.frames import warp_frame
from stabilize.warp.homography import homography
from stabilize.warp.render import batches


def test_the_batched_torch_warp_matches_opencv():
    # The CUDA path (kornia), run on the CPU here: the same pixels as cv2.warpPerspective.
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


def rolling_path(n: int, size: tuple[int, int]) -> CameraPath:
    """A path whose frames are warped row by row: turns that grow down the frame."""
    h = size[0]
    K = intrinsics(90.0, size)
    rows = np.linspace(-0.5, h - 0.5, 17)
    axes = np.random.default_rng(2).normal(0, 0.02, (n, 1, 3))
    C = so3.exp_so3(axes * (rows[None, :, None] / h - 0.5))  # (n, 17, 3, 3)
    eye = np.tile(np.eye(3), (n, 1, 1))
    H = np.stack([homography(K, c[8], 1.1) for c in C])
    return CameraPath(
        np.arange(n) / 30, eye[:-1], np.ones(n - 1), eye, eye, np.full(n, 1.1), H, K, C, rows
    )


def test_the_batched_torch_remap_matches_opencvs_row_by_row_warp():
    # The CUDA path of a rolling shutter's maps, run on the CPU: RGB and I420 alike.
    path = rolling_path(3, (60, 80))
    rng = np.random.default_rng(3)
    for shape in ((60, 80, 3), (90, 80)):
        frames = rng.integers(0, 255, (3, *shape), np.uint8)
        items = list(enumerate(frames))
        cv_out = np.stack(path.warp_many(items, "cpu"))
        torch_out = np.stack(path.warp_together(items, "cpu"))
        diff = np.abs(torch_out.astype(int) - cv_out)
        assert diff.mean() < 0.1 and diff.max() <= 2
