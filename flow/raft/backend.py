"""RAFT as a flow backend: padding, batching, and each frame encoded once."""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator

import numpy as np
import torch
import torch.nn.functional as F
from numpy.typing import NDArray

from flow.base import check_frame, check_pair, to_rgb
from flow.raft.network import RAFT
from flow.raft.weights import find_weights, load_checkpoint, to_official


def pick_device(device: str | None) -> torch.device:
    if device is None:
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise ValueError("device 'cuda' was asked for, but torch sees no CUDA device")
    return torch.device(device)


MIN_SIDE = 128  # below this the coarsest correlation level would be a single pixel


def padding(h: int, w: int) -> tuple[int, int, int, int]:
    """(left, right, top, bottom) up to multiples of 8, split evenly, extra on the far side.

    This is the official demo's InputPadder in its default ('sintel') mode, except
    that frames smaller than 128 px are padded up to 128, as the network needs.
    """
    ph, pw = max((-h) % 8, MIN_SIDE - h), max((-w) % 8, MIN_SIDE - w)
    return pw // 2, pw - pw // 2, ph // 2, ph - ph // 2


class RaftFlow:
    """RAFT optical flow (small or large) from published weights.

    Args:
        variant: ``"small"`` or ``"large"``.
        weights: checkpoint path; else ``$STABILIZE_RAFT_WEIGHTS``, else the user cache
            (see :mod:`flow.raft.weights`).
        iters: GRU updates per pair (12 as in the official demo; 20 is a little better).
        device: ``"cpu"`` or ``"cuda"``; default cuda when available.
        batch_size: frame pairs per network call in :meth:`many` (default 8 on CUDA, 1
            on the CPU, where batching gains nothing and costs memory).
    """

    def __init__(
        self,
        variant: str = "small",
        *,
        weights: str | os.PathLike | None = None,
        iters: int = 12,
        device: str | None = None,
        batch_size: int | None = None,
    ) -> None:
        if iters < 1:
            raise ValueError(f"iters must be at least 1, got {iters}")
        path = find_weights(variant, weights)
        state, found = to_official(load_checkpoint(path))
        if found != variant:
            raise ValueError(f"{path} holds RAFT-{found} weights, not RAFT-{variant}")
        self.variant = variant
        self.name = "raft" if variant == "small" else "raft-large"
        self.iters = iters
        self.device = pick_device(device)
        self.batch_size = batch_size or (8 if self.device.type == "cuda" else 1)
        self.model = RAFT(variant)
        self.model.load_state_dict(state, strict=True)
        self.model.eval().to(self.device)
        # Channels-last lets oneDNN skip a layout conversion in every convolution: the
        # update block and the context encoder run 1.5–2× faster on the CPU. The feature
        # encoder stays channels-first, where its instance norms are faster.
        self.model.update_block.to(memory_format=torch.channels_last)
        self.model.cnet.to(memory_format=torch.channels_last)

    def __call__(self, frame0: NDArray, frame1: NDArray) -> NDArray[np.float32]:
        frame0, frame1 = check_pair(frame0, frame1)
        pad = padding(*frame0.shape[:2])
        images = self._tensors([frame0, frame1], pad)
        with torch.inference_mode():
            _, up = self.model(images[:1], images[1:], iters=self.iters)
        return self._unpad(up, pad)[0]

    def many(self, frames: Iterable[NDArray]) -> Iterator[NDArray[np.float32]]:
        """Flows of consecutive pairs; frames are encoded once, pairs run in batches."""
        held: tuple | None = None  # (size, features, hidden, context) of the last frame
        chunk: list[NDArray] = []
        for frame in frames:
            chunk.append(check_frame(frame))
            if len(chunk) == self.batch_size + (held is None):
                held = yield from self._run_chunk(chunk, held)
                chunk = []
        if chunk:
            yield from self._run_chunk(chunk, held)

    def _run_chunk(self, chunk: list[NDArray], held: tuple | None):
        size = chunk[0].shape[:2]
        if any(f.shape[:2] != size for f in chunk) or (held is not None and held[0] != size):
            raise ValueError("frame sizes differ within the sequence")
        pad = padding(*size)
        with torch.inference_mode():
            images = self._tensors(chunk, pad)
            fmaps = self.model.features(images)
            net, inp = self.model.context(images)
            if held is not None:
                fmaps = torch.cat([held[1], fmaps])
                net, inp = torch.cat([held[2], net]), torch.cat([held[3], inp])
            n = fmaps.shape[0] - 1
            if n > 0:
                _, up = self.model.iterate(fmaps[:n], fmaps[1:], net[:n], inp[:n], self.iters)
                yield from self._unpad(up, pad)
        return size, fmaps[-1:], net[-1:], inp[-1:]

    def _tensors(self, frames: list[NDArray], pad: tuple[int, int, int, int]) -> torch.Tensor:
        batch = np.stack([to_rgb(f) for f in frames]).astype(np.float32)
        images = torch.from_numpy(batch).permute(0, 3, 1, 2).to(self.device)
        return F.pad(images, pad, mode="replicate") if any(pad) else images.contiguous()

    @staticmethod
    def _unpad(flow: torch.Tensor, pad: tuple[int, int, int, int]) -> NDArray[np.float32]:
        left, right, top, bottom = pad
        h, w = flow.shape[-2:]
        flow = flow[..., top : h - bottom, left : w - right]
        return flow.permute(0, 2, 3, 1).float().cpu().numpy()
