"""Batched homography warps with kornia, for CUDA."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def warp_frames_torch(
    frames: NDArray[np.uint8], H: NDArray, device: str = "cuda", fill: int = 0
) -> NDArray[np.uint8]:
    """Warp a batch (B, H, W) or (B, H, W, C) by homographies (B, 3, 3) with kornia on
    ``device``, ``fill`` outside.

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
    out = kornia.geometry.transform.warp_perspective(src, M, (h, w), align_corners=True)
    out = (out + fill).round_().clamp_(0, 255).to(torch.uint8)
    out = out[:, 0] if planar else out.permute(0, 2, 3, 1)
    return out.cpu().numpy()
