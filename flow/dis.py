"""OpenCV's Dense Inverse Search flow (Kroeger et al. 2016): the fast CPU default."""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import cv2
import numpy as np
from numpy.typing import NDArray

from flow.base import check_frame, check_pair, to_grey

PRESETS = {
    "ultrafast": cv2.DISOPTICAL_FLOW_PRESET_ULTRAFAST,
    "fast": cv2.DISOPTICAL_FLOW_PRESET_FAST,
    "medium": cv2.DISOPTICAL_FLOW_PRESET_MEDIUM,
}


class DISFlow:
    """DIS optical flow on grey frames.

    Args:
        preset: ``"ultrafast"``, ``"fast"`` (default: about 5 ms per 480×270 pair on
            one core, and accurate enough for the rotation vote) or ``"medium"``.
    """

    name = "dis"

    def __init__(self, preset: str = "fast") -> None:
        if preset not in PRESETS:
            raise ValueError(f"DIS preset must be one of {sorted(PRESETS)}, got {preset!r}")
        self.preset = preset
        self._dis = cv2.DISOpticalFlow_create(PRESETS[preset])

    def __call__(self, frame0: NDArray, frame1: NDArray) -> NDArray[np.float32]:
        frame0, frame1 = check_pair(frame0, frame1)
        return self._flow(to_grey(frame0), to_grey(frame1))

    def many(self, frames: Iterable[NDArray]) -> Iterator[NDArray[np.float32]]:
        previous = None
        for frame in frames:
            grey = to_grey(check_frame(frame))
            if previous is not None:
                if grey.shape != previous.shape:
                    raise ValueError(
                        f"frame sizes differ: {previous.shape[::-1]} and {grey.shape[::-1]}"
                    )
                yield self._flow(previous, grey)
            previous = grey

    def _flow(self, grey0: NDArray[np.uint8], grey1: NDArray[np.uint8]) -> NDArray[np.float32]:
        return self._dis.calc(grey0, grey1, None).astype(np.float32, copy=False)
