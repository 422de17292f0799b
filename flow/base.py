"""What every flow backend shares: the call protocol and input checks.

A backend is called as ``backend(frame0, frame1) -> flow`` with frames as uint8 RGB
(H, W, 3) or grey (H, W), and returns float32 (H, W, 2) forward flow: u then v, in
pixels, from frame0 to frame1 (CONVENTIONS.md). ``backend.many(frames)`` yields the
flows of consecutive pairs from an iterable of frames, encoding each frame once.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import Protocol

import cv2
import numpy as np
from numpy.typing import NDArray


class FlowBackend(Protocol):
    name: str

    def __call__(self, frame0: NDArray, frame1: NDArray) -> NDArray[np.float32]: ...

    def many(self, frames: Iterable[NDArray]) -> Iterator[NDArray[np.float32]]: ...


def check_frame(frame: NDArray) -> NDArray[np.uint8]:
    """A uint8 RGB (H, W, 3) or grey (H, W) frame, or a clear ValueError."""
    frame = np.asarray(frame)
    if frame.dtype != np.uint8:
        raise ValueError(f"frames must be uint8 images, got dtype {frame.dtype}")
    if not (frame.ndim == 2 or (frame.ndim == 3 and frame.shape[2] in (1, 3))):
        raise ValueError(f"frames must be (H, W) grey or (H, W, 3) RGB, got shape {frame.shape}")
    if min(frame.shape[:2]) < 8:
        h, w = frame.shape[:2]
        raise ValueError(f"frames must be at least 8×8 pixels, got {w}×{h}")
    return frame


def check_pair(frame0: NDArray, frame1: NDArray) -> tuple[NDArray, NDArray]:
    frame0, frame1 = check_frame(frame0), check_frame(frame1)
    if frame0.shape[:2] != frame1.shape[:2]:
        raise ValueError(
            f"frame sizes differ: {frame0.shape[1]}×{frame0.shape[0]} "
            f"and {frame1.shape[1]}×{frame1.shape[0]}"
        )
    return frame0, frame1


def to_grey(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    if frame.ndim == 2:
        return frame
    if frame.shape[2] == 1:
        return frame[..., 0]
    return cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)


def to_rgb(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    if frame.ndim == 2:
        return np.repeat(frame[..., None], 3, axis=2)
    if frame.shape[2] == 1:
        return np.repeat(frame, 3, axis=2)
    return frame
