"""RAFT's feature and context encoders: a 7×7 stride-2 stem and three residual stages.

Both downsample by 8. The small model uses bottleneck blocks (widths 32, 64, 96), the
large one plain residual blocks (64, 96, 128). Module names follow the official
checkpoints (princeton-vl/RAFT), so their state dicts load unchanged.
"""

from __future__ import annotations

import torch
from torch import nn


def norm_layer(kind: str, channels: int) -> nn.Module:
    """``instance`` (no affine, as in RAFT), ``batch``, or ``none`` (an empty Sequential)."""
    if kind == "instance":
        return nn.InstanceNorm2d(channels)
    if kind == "batch":
        return nn.BatchNorm2d(channels)
    if kind == "none":
        return nn.Sequential()
    raise ValueError(f"unknown norm {kind!r}")


class ResidualBlock(nn.Module):
    """Two 3×3 convolutions with norm and ReLU, plus a projected shortcut when striding."""

    def __init__(self, in_planes: int, planes: int, norm: str, stride: int = 1) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(in_planes, planes, 3, padding=1, stride=stride)
        self.conv2 = nn.Conv2d(planes, planes, 3, padding=1)
        self.relu = nn.ReLU(inplace=True)
        self.norm1 = norm_layer(norm, planes)
        self.norm2 = norm_layer(norm, planes)
        self.downsample: nn.Module | None = None
        if stride != 1:
            # The official code registers this norm twice (norm3 and downsample.1).
            self.norm3 = norm_layer(norm, planes)
            self.downsample = nn.Sequential(
                nn.Conv2d(in_planes, planes, 1, stride=stride), self.norm3
            )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = self.relu(self.norm1(self.conv1(x)))
        y = self.relu(self.norm2(self.conv2(y)))
        if self.downsample is not None:
            x = self.downsample(x)
        return self.relu(x + y)


class BottleneckBlock(nn.Module):
    """1×1 → 3×3 → 1×1 convolutions at a quarter of the width, with norm and ReLU."""

    def __init__(self, in_planes: int, planes: int, norm: str, stride: int = 1) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(in_planes, planes // 4, 1)
        self.conv2 = nn.Conv2d(planes // 4, planes // 4, 3, padding=1, stride=stride)
        self.conv3 = nn.Conv2d(planes // 4, planes, 1)
        self.relu = nn.ReLU(inplace=True)
        self.norm1 = norm_layer(norm, planes // 4)
        self.norm2 = norm_layer(norm, planes // 4)
        self.norm3 = norm_layer(norm, planes)
        self.downsample: nn.Module | None = None
        if stride != 1:
            self.norm4 = norm_layer(norm, planes)
            self.downsample = nn.Sequential(
                nn.Conv2d(in_planes, planes, 1, stride=stride), self.norm4
            )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = self.relu(self.norm1(self.conv1(x)))
        y = self.relu(self.norm2(self.conv2(y)))
        y = self.relu(self.norm3(self.conv3(y)))
        if self.downsample is not None:
            x = self.downsample(x)
        return self.relu(x + y)


class Encoder(nn.Module):
    """Image (B, 3, H, W) in [-1, 1] → features (B, output_dim, H/8, W/8)."""

    def __init__(self, output_dim: int, norm: str, small: bool) -> None:
        super().__init__()
        block = BottleneckBlock if small else ResidualBlock
        widths = (32, 64, 96) if small else (64, 96, 128)
        stem = 32 if small else 64
        self.norm1 = norm_layer(norm, stem)
        self.conv1 = nn.Conv2d(3, stem, 7, stride=2, padding=3)
        self.relu1 = nn.ReLU(inplace=True)
        layers, in_planes = [], stem
        for width, stride in zip(widths, (1, 2, 2), strict=True):
            layers.append(
                nn.Sequential(block(in_planes, width, norm, stride), block(width, width, norm, 1))
            )
            in_planes = width
        self.layer1, self.layer2, self.layer3 = layers
        self.conv2 = nn.Conv2d(in_planes, output_dim, 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        x = self.relu1(self.norm1(self.conv1(x)))
        x = self.layer3(self.layer2(self.layer1(x)))
        return self.conv2(x)
