"""Batched warps for CUDA: homographies with kornia, smooth maps with torch's grid_sample."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.warp.border import torch_padding


def warp_frames_torch(
    frames: NDArray[np.uint8],
    H: NDArray,
    device: str = "cuda",
    fill: int = 0,
    border: str = "black",
) -> NDArray[np.uint8]:
    """Warp a batch (B, H, W) or (B, H, W, C) by homographies (B, 3, 3) with kornia on
    ``device``, ``fill`` outside (or the ``border`` named: :mod:`stabilize.warp.border`).

    The same mapping as :func:`warp_frame` (pixel centres at integers, bilinear), for
    CUDA, where one batched call beats a frame at a time. On the CPU, OpenCV is about 20×
    faster than this.
    """
    import kornia
    import torch

    planar = frames.ndim == 3
    src = torch.from_numpy(np.ascontiguousarray(frames)).to(device)
    src = (src[:, None] if planar else src.permute(0, 3, 1, 2)).float() - fill
    M = torch.as_tensor(np.asarray(H), dtype=torch.float32, device=device)
    h, w = frames.shape[1:3]
    # Warping (x - fill) with zero padding, then adding fill back, pads with fill.
    out = kornia.geometry.transform.warp_perspective(
        src, M, (h, w), align_corners=True, padding_mode=torch_padding(border)
    )
    out = (out + fill).round_().clamp_(0, 255).to(torch.uint8)
    out = out[:, 0] if planar else out.permute(0, 2, 3, 1)
    return out.cpu().numpy()


def remap_frames_torch(
    frames: NDArray,
    coarse: NDArray,
    device: str = "cuda",
    fill: int = 0,
    half: bool = False,
    border: str = "black",
) -> NDArray:
    """Warp a batch (B, H, W) or (B, H, W, C) by smooth maps given at their knots
    (B, rows, cols, 2: input pixels, :func:`stabilize.warp.remap.coarse_map` of the
    full-size frame), ``fill`` outside, on ``device``; with ``half``, the frames are
    chroma planes at half the maps' size; ``border`` as :func:`warp_frames_torch`'s.

    The knots go to the device rather than the dense maps (0.2 MB a 1080p frame instead
    of 16); there they are interpolated and sampled bilinearly, as
    :func:`stabilize.warp.remap.remap_from` does on the CPU.
    """
    import torch
    import torch.nn.functional as F

    from stabilize.warp.remap import MAP_STEP, half_knots

    planar = frames.ndim == 3
    src = torch.from_numpy(np.ascontiguousarray(frames)).to(device)
    src = (src[:, None] if planar else src.permute(0, 3, 1, 2)).float() - fill
    h, w = frames.shape[1:3]
    step = MAP_STEP // 2 if half else MAP_STEP
    knots = np.asarray(half_knots(coarse) if half else coarse)
    knots = torch.as_tensor(knots, dtype=torch.float32, device=device)
    # Knots at cell centres one cell beyond the frame: the half-pixel convention of
    # align_corners=False interpolates them exactly, as cv2.resize does.
    up = F.interpolate(knots.permute(0, 3, 1, 2), scale_factor=step, mode="bilinear")
    dense = up[:, :, step : step + h, step : step + w]
    scale = torch.tensor([2.0 / max(w - 1, 1), 2.0 / max(h - 1, 1)], device=device)
    grid = dense.permute(0, 2, 3, 1) * scale - 1.0  # pixels → grid_sample's [-1, 1]
    padding = torch_padding(border)
    out = F.grid_sample(src, grid, mode="bilinear", padding_mode=padding, align_corners=True)
    out = (out + fill).round_().clamp_(0, 255).to(torch.uint8)
    out = out[:, 0] if planar else out.permute(0, 2, 3, 1)
    return out.cpu().numpy()
