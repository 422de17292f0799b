"""RAFT's update operator: motion encoder, convolutional GRU and flow head.

Each iteration encodes the correlation features and the current flow, runs one GRU
step on [context, motion], and predicts a flow increment. The context's share of the
GRU's convolutions is the same in every iteration, so it is computed once per pair
(:func:`plan_gru`), which saves a quarter of the update's arithmetic. The large model also
predicts the convex-upsampling mask.
"""

from __future__ import annotations

from typing import NamedTuple

import torch
import torch.nn.functional as F
from torch import nn


class SmallMotionEncoder(nn.Module):
    def __init__(self, corr_channels: int) -> None:
        super().__init__()
        self.convc1 = nn.Conv2d(corr_channels, 96, 1)
        self.convf1 = nn.Conv2d(2, 64, 7, padding=3)
        self.convf2 = nn.Conv2d(64, 32, 3, padding=1)
        self.conv = nn.Conv2d(128, 80, 3, padding=1)

    def forward(self, flow: torch.Tensor, corr: torch.Tensor) -> torch.Tensor:
        c = F.relu(self.convc1(corr))
        f = F.relu(self.convf2(F.relu(self.convf1(flow))))
        return torch.cat([F.relu(self.conv(torch.cat([c, f], dim=1))), flow], dim=1)


class BasicMotionEncoder(nn.Module):
    def __init__(self, corr_channels: int) -> None:
        super().__init__()
        self.convc1 = nn.Conv2d(corr_channels, 256, 1)
        self.convc2 = nn.Conv2d(256, 192, 3, padding=1)
        self.convf1 = nn.Conv2d(2, 128, 7, padding=3)
        self.convf2 = nn.Conv2d(128, 64, 3, padding=1)
        self.conv = nn.Conv2d(64 + 192, 128 - 2, 3, padding=1)

    def forward(self, flow: torch.Tensor, corr: torch.Tensor) -> torch.Tensor:
        c = F.relu(self.convc2(F.relu(self.convc1(corr))))
        f = F.relu(self.convf2(F.relu(self.convf1(flow))))
        return torch.cat([F.relu(self.conv(torch.cat([c, f], dim=1))), flow], dim=1)


class GRUPlan(NamedTuple):
    """One GRU step's weights, split for a fixed context input.

    The GRU sees [h, context, motion]; the context is the same in every iteration,
    so its share of each gate's convolution (with the bias) is computed once per
    pair, and the z and r gates share one convolution over [h, motion].
    """

    w_zr: torch.Tensor
    zr_const: torch.Tensor
    w_q: torch.Tensor
    q_const: torch.Tensor
    padding: tuple[int, int]


def plan_gru(
    convz: nn.Conv2d, convr: nn.Conv2d, convq: nn.Conv2d, hidden: int, inp: torch.Tensor
) -> GRUPlan:
    """Split the gates' weights by input block: hidden state, context, motion."""
    ctx = slice(hidden, hidden + inp.shape[1])
    pad = convz.padding

    layout = torch.channels_last if inp.is_contiguous(memory_format=torch.channels_last) else None

    def weights(w: torch.Tensor) -> torch.Tensor:
        # Weights in the activations' memory layout, or oneDNN converts on every call.
        return w.contiguous(memory_format=layout) if layout else w.contiguous()

    def parts(conv: nn.Conv2d) -> tuple[torch.Tensor, torch.Tensor]:
        w = conv.weight
        own = torch.cat([w[:, :hidden], w[:, ctx.stop :]], dim=1)
        return own, F.conv2d(inp, weights(w[:, ctx]), conv.bias, padding=pad)

    (wz, cz), (wr, cr), (wq, cq) = parts(convz), parts(convr), parts(convq)
    zr_const = torch.cat([cz, cr], dim=1)
    return GRUPlan(weights(torch.cat([wz, wr])), zr_const, weights(wq), cq, pad)


def gru_step(plan: GRUPlan, h: torch.Tensor, motion: torch.Tensor) -> torch.Tensor:
    """h ← (1 - z) h + z q, with z, r gates and candidate q from [h, context, motion]."""
    zr = torch.sigmoid(
        F.conv2d(torch.cat([h, motion], dim=1), plan.w_zr, padding=plan.padding) + plan.zr_const
    )
    z, r = zr.chunk(2, dim=1)
    q = F.conv2d(torch.cat([r * h, motion], dim=1), plan.w_q, padding=plan.padding)
    q = torch.tanh(q + plan.q_const)
    return (1 - z) * h + z * q


class ConvGRU(nn.Module):
    """3×3 convolutional GRU (small model)."""

    def __init__(self, hidden: int, inputs: int) -> None:
        super().__init__()
        self.hidden = hidden
        self.convz = nn.Conv2d(hidden + inputs, hidden, 3, padding=1)
        self.convr = nn.Conv2d(hidden + inputs, hidden, 3, padding=1)
        self.convq = nn.Conv2d(hidden + inputs, hidden, 3, padding=1)

    def plan(self, inp: torch.Tensor) -> tuple[GRUPlan, ...]:
        return (plan_gru(self.convz, self.convr, self.convq, self.hidden, inp),)

    def forward(self, h: torch.Tensor, motion: torch.Tensor, plans: tuple) -> torch.Tensor:
        return gru_step(plans[0], h, motion)


class SepConvGRU(nn.Module):
    """A 1×5 then a 5×1 GRU step (large model)."""

    def __init__(self, hidden: int, inputs: int) -> None:
        super().__init__()
        self.hidden = hidden
        c = hidden + inputs
        self.convz1 = nn.Conv2d(c, hidden, (1, 5), padding=(0, 2))
        self.convr1 = nn.Conv2d(c, hidden, (1, 5), padding=(0, 2))
        self.convq1 = nn.Conv2d(c, hidden, (1, 5), padding=(0, 2))
        self.convz2 = nn.Conv2d(c, hidden, (5, 1), padding=(2, 0))
        self.convr2 = nn.Conv2d(c, hidden, (5, 1), padding=(2, 0))
        self.convq2 = nn.Conv2d(c, hidden, (5, 1), padding=(2, 0))

    def plan(self, inp: torch.Tensor) -> tuple[GRUPlan, ...]:
        return (
            plan_gru(self.convz1, self.convr1, self.convq1, self.hidden, inp),
            plan_gru(self.convz2, self.convr2, self.convq2, self.hidden, inp),
        )

    def forward(self, h: torch.Tensor, motion: torch.Tensor, plans: tuple) -> torch.Tensor:
        return gru_step(plans[1], gru_step(plans[0], h, motion), motion)


class FlowHead(nn.Module):
    def __init__(self, inputs: int, hidden: int) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(inputs, hidden, 3, padding=1)
        self.conv2 = nn.Conv2d(hidden, 2, 3, padding=1)
        self.relu = nn.ReLU(inplace=True)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.conv2(self.relu(self.conv1(x)))


class SmallUpdateBlock(nn.Module):
    def __init__(self, corr_channels: int, hidden: int = 96, context: int = 64) -> None:
        super().__init__()
        self.encoder = SmallMotionEncoder(corr_channels)
        self.gru = ConvGRU(hidden, 82 + context)
        self.flow_head = FlowHead(hidden, 128)

    def forward(self, net, plans, corr, flow):
        """(hidden state, upsampling mask or None, flow increment); plans = gru.plan(inp)."""
        net = self.gru(net, self.encoder(flow, corr), plans)
        return net, None, self.flow_head(net)


class BasicUpdateBlock(nn.Module):
    def __init__(self, corr_channels: int, hidden: int = 128, context: int = 128) -> None:
        super().__init__()
        self.encoder = BasicMotionEncoder(corr_channels)
        self.gru = SepConvGRU(hidden, 128 + context)
        self.flow_head = FlowHead(hidden, 256)
        self.mask = nn.Sequential(
            nn.Conv2d(hidden, 256, 3, padding=1), nn.ReLU(inplace=True), nn.Conv2d(256, 64 * 9, 1)
        )

    def forward(self, net, plans, corr, flow):
        net = self.gru(net, self.encoder(flow, corr), plans)
        # The official model scales the mask by 0.25 (to balance its gradients).
        return net, 0.25 * self.mask(net), self.flow_head(net)
