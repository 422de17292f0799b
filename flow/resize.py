"""Choosing and applying the working size at which flow is computed.

Backends compute flow at exactly the size of the frames they are given; resizing is
this separate, explicit step. The paper computed flow at 480×270, so the default
working size has about 480 px on the long side, with the aspect ratio kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

DEFAULT_LONG_SIDE = 480


@dataclass(frozen=True)
class WorkingSize:
    """Frames of ``source`` (H, W) are resized to ``size`` (h, w).

    ``scale`` is (sx, sy) = (w / W, h / H): flow in working pixels times 1/scale is
    flow in source pixels, and a focal length f in source pixels becomes sx·f
    (see :func:`rotation.camera.scale_intrinsics`).
    """

    source: tuple[int, int]
    size: tuple[int, int]

    @property
    def scale(self) -> tuple[float, float]:
        return (self.size[1] / self.source[1], self.size[0] / self.source[0])

    def resize(self, frame: NDArray) -> NDArray:
        """Resize a frame of the source size (area averaging when shrinking)."""
        if frame.shape[:2] != self.source:
            raise ValueError(
                f"frame is {frame.shape[1]}×{frame.shape[0]}, expected "
                f"{self.source[1]}×{self.source[0]}"
            )
        if self.size == self.source:
            return frame
        shrink = self.size[0] < self.source[0]
        interpolation = cv2.INTER_AREA if shrink else cv2.INTER_LINEAR
        return cv2.resize(frame, (self.size[1], self.size[0]), interpolation=interpolation)

    def flow_to_source(self, flow: NDArray[np.float32]) -> NDArray[np.float32]:
        """Flow at the working size, resampled and rescaled to source pixels."""
        sx, sy = self.scale
        out = cv2.resize(flow, (self.source[1], self.source[0]), interpolation=cv2.INTER_LINEAR)
        return (out / np.array([sx, sy], np.float32)).astype(np.float32)


def working_size(
    source: tuple[int, int], long_side: int | None = DEFAULT_LONG_SIDE, multiple: int = 1
) -> WorkingSize:
    """The working size for frames of (H, W): ``long_side`` px on the long side.

    The result never enlarges the frames. ``multiple`` rounds each side to a multiple
    (use 8 for a network that needs it, or let the RAFT backend pad instead).
    ``long_side=None`` keeps the source size.
    """
    h, w = int(source[0]), int(source[1])
    if h < 1 or w < 1:
        raise ValueError(f"frame size must be positive, got {w}×{h}")
    s = 1.0 if long_side is None else min(1.0, long_side / max(h, w))
    size = (
        max(multiple, round(h * s / multiple) * multiple),
        max(multiple, round(w * s / multiple) * multiple),
    )
    return WorkingSize((h, w), size)
