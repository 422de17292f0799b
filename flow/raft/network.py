"""The RAFT network (Teed & Deng, ECCV 2020), small and large variants.

Frames are encoded once into 1/8-resolution features (``fnet``) and context
(``cnet``: the GRU's initial hidden state, through tanh, and its context input,
through ReLU). For a pair, the correlation pyramid of the two feature maps is built,
and ``iters`` GRU updates refine the flow from zero. The small model upsamples the
1/8 flow bilinearly; the large one with its learned convex mask.

Inputs are raw 0..255 RGB (B, 3, H, W) with H and W multiples of 8; the network maps
them to [-1, 1] itself, as the official code does.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
import torch.nn.functional as F
from torch import nn

from flow.raft.corr import correlation_pyramid, lookup
from flow.raft.encoder import Encoder
from flow.raft.update import BasicUpdateBlock, SmallUpdateBlock


@dataclass(frozen=True)
class Variant:
    name: str
    small: bool
    feature_dim: int
    hidden: int
    context: int
    radius: int
    levels: int = 4

    @property
    def corr_channels(self) -> int:
        return self.levels * (2 * self.radius + 1) ** 2


VARIANTS = {
    "small": Variant("small", True, feature_dim=128, hidden=96, context=64, radius=3),
    "large": Variant("large", False, feature_dim=256, hidden=128, context=128, radius=4),
}


def normalise(images: torch.Tensor) -> torch.Tensor:
    return 2 * (images / 255.0) - 1.0


def coords_grid(batch: int, h: int, w: int, device: torch.device) -> torch.Tensor:
    """Pixel coordinates (B, 2, h, w), channel 0 = x (column), 1 = y (row)."""
    ys, xs = torch.meshgrid(
        torch.arange(h, device=device), torch.arange(w, device=device), indexing="ij"
    )
    return torch.stack([xs, ys], dim=0).float()[None].repeat(batch, 1, 1, 1)


def upsample_bilinear(flow: torch.Tensor) -> torch.Tensor:
    """1/8 flow (B, 2, h, w) → full resolution, values scaled by 8."""
    h, w = flow.shape[-2:]
    return 8 * F.interpolate(flow, size=(8 * h, 8 * w), mode="bilinear", align_corners=True)


def upsample_convex(flow: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Each full-resolution pixel is a softmax-weighted mix of its 3×3 coarse neighbours."""
    b, _, h, w = flow.shape
    mask = torch.softmax(mask.view(b, 1, 9, 8, 8, h, w), dim=2)
    neighbours = F.unfold(8 * flow, [3, 3], padding=1).view(b, 2, 9, 1, 1, h, w)
    up = torch.sum(mask * neighbours, dim=2).permute(0, 1, 4, 2, 5, 3)
    return up.reshape(b, 2, 8 * h, 8 * w)


class RAFT(nn.Module):
    def __init__(self, variant: str = "small") -> None:
        super().__init__()
        if variant not in VARIANTS:
            raise ValueError(f"RAFT variant must be one of {sorted(VARIANTS)}, got {variant!r}")
        v = self.variant = VARIANTS[variant]
        self.fnet = Encoder(v.feature_dim, "instance", v.small)
        self.cnet = Encoder(v.hidden + v.context, "none" if v.small else "batch", v.small)
        block = SmallUpdateBlock if v.small else BasicUpdateBlock
        self.update_block = block(v.corr_channels, v.hidden, v.context)

    def features(self, images: torch.Tensor) -> torch.Tensor:
        """Matching features (B, D, H/8, W/8) of raw 0..255 images."""
        return self.fnet(normalise(images)).float()

    def context(self, images: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """(initial hidden state, context input) of the GRU, for the first frames of pairs."""
        layout = torch.channels_last  # see RaftFlow: cnet and the update block use it
        out = self.cnet(normalise(images).contiguous(memory_format=layout))
        net, inp = torch.split(out, [self.variant.hidden, self.variant.context], dim=1)
        net = torch.tanh(net).contiguous(memory_format=layout)
        return net, torch.relu(inp).contiguous(memory_format=layout)

    def iterate(
        self,
        fmap1: torch.Tensor,
        fmap2: torch.Tensor,
        net: torch.Tensor,
        inp: torch.Tensor,
        iters: int,
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """(1/8 flow, full-resolution flow) after ``iters`` updates from zero flow."""
        pyramid = correlation_pyramid(fmap1, fmap2, self.variant.levels)
        b, _, h, w = fmap1.shape
        coords0 = coords_grid(b, h, w, fmap1.device)
        coords1 = coords0.clone()
        mask = None
        plans = self.update_block.gru.plan(inp)
        for _ in range(iters):
            corr = lookup(pyramid, coords1, self.variant.radius)
            net, mask, delta = self.update_block(net, plans, corr, coords1 - coords0)
            coords1 = coords1 + delta
        low = coords1 - coords0
        up = upsample_bilinear(low) if mask is None else upsample_convex(low, mask)
        return low, up

    def forward(
        self, image1: torch.Tensor, image2: torch.Tensor, iters: int = 12
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """The official test-mode call: (1/8 flow, full-resolution flow) from image1 to image2."""
        fmaps = self.features(torch.cat([image1, image2], dim=0))
        fmap1, fmap2 = fmaps.chunk(2, dim=0)
        net, inp = self.context(image1)
        return self.iterate(fmap1, fmap2, net, inp, iters)
