"""The all-pairs correlation pyramid and its lookup (RAFT §3.2).

corr(i, j) = ⟨f₁(i), f₂(j)⟩ / √D for every pixel pair of the two 1/8-resolution
feature maps, average-pooled 2×2 over the frame-1 dimensions into ``levels`` levels.
A lookup samples a (2r+1)² window around each pixel's current match at every level,
bilinearly (align_corners, zeros outside). Within a level the window's x offset is
the slow index, as in the official code; levels are concatenated finest first.
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F


def correlation_pyramid(
    fmap1: torch.Tensor, fmap2: torch.Tensor, levels: int
) -> list[torch.Tensor]:
    """Volumes of shape (B·h·w, 1, h / 2^l, w / 2^l), finest first."""
    b, d, h, w = fmap1.shape
    f1 = fmap1.reshape(b, d, h * w).transpose(1, 2)
    # The 1/√D scale rides on the matrix product instead of a pass over the volume.
    empty = torch.empty(b, h * w, h * w, dtype=f1.dtype, device=f1.device)
    corr = torch.baddbmm(empty, f1, fmap2.reshape(b, d, h * w), beta=0, alpha=1 / math.sqrt(d))
    corr = corr.view(b * h * w, 1, h, w)
    pyramid = [corr]
    for _ in range(levels - 1):
        corr = pool2(corr)
        pyramid.append(corr)
    return pyramid


def pool2(volume: torch.Tensor) -> torch.Tensor:
    """avg_pool2d(volume, 2, stride=2) of (N, 1, H, W), an odd last row or column
    dropped as there; written as a reshape, it is several times faster for a batch of
    thousands of single-channel maps."""
    n, _, h, w = volume.shape
    v = volume[:, 0, : h // 2 * 2, : w // 2 * 2].reshape(n, 1, h // 2, 2, w // 2, 2)
    return (
        v[:, :, :, 0, :, 0] + v[:, :, :, 0, :, 1] + v[:, :, :, 1, :, 0] + v[:, :, :, 1, :, 1]
    ) / 4


def window(radius: int, device: torch.device) -> torch.Tensor:
    """Offsets (1, 2r+1, 2r+1, 2): entry [a, b] is (d[a], d[b]) added to (x, y)."""
    d = torch.linspace(-radius, radius, 2 * radius + 1, device=device)
    return torch.stack(torch.meshgrid(d, d, indexing="ij"), dim=-1).view(
        1, 2 * radius + 1, 2 * radius + 1, 2
    )


def lookup(pyramid: list[torch.Tensor], coords: torch.Tensor, radius: int) -> torch.Tensor:
    """Correlation features (B, levels·(2r+1)², h, w) around coords (B, 2, h, w)."""
    b, _, h, w = coords.shape
    centres = coords.permute(0, 2, 3, 1).reshape(b * h * w, 1, 1, 2)
    offsets = window(radius, coords.device)
    out = []
    for level, corr in enumerate(pyramid):
        grid = centres / 2**level + offsets
        out.append(sample(corr, grid).view(b, h, w, -1))
    # (B, h, w, C) viewed as (B, C, h, w) is already channels-last: no copy needed.
    return torch.cat(out, dim=-1).permute(0, 3, 1, 2)


def sample(image: torch.Tensor, coords: torch.Tensor) -> torch.Tensor:
    """Bilinear samples at pixel coordinates (x, y): grid_sample with align_corners."""
    H, W = image.shape[-2:]
    x, y = coords.split([1, 1], dim=-1)
    grid = torch.cat([2 * x / (W - 1) - 1, 2 * y / (H - 1) - 1], dim=-1)
    return F.grid_sample(image, grid, align_corners=True)
