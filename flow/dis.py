"""OpenCV's Dense Inverse Search flow (Kroeger et al. 2016): the fast CPU default."""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import cv2
import numpy as np
from numpy.typing import NDArray

from flow.base import check_frame, check_pair, to_grey

# A preset's name → (OpenCV's preset, the finest pyramid level the flow is refined at).
# OpenCV's own "fast" stops at level 2, a quarter of the working size (120 px across at
# 480): the flow comes out too smooth there to keep the x²/f terms a turn makes at the
# frame's edges, and the focal length estimated from them was 10–11% long on a rendered
# 45° pure rotation and 5–6% on the rendered walks (+2.1% and -0.9..0.8% at level 1,
# medium +1.4%). So "fast" here is refined down to level 1: 5.9 ms a 480×270 pair
# instead of 2.1 (medium: 7.9).
PRESETS = {
    "ultrafast": (cv2.DISOPTICAL_FLOW_PRESET_ULTRAFAST, 2),
    "fast": (cv2.DISOPTICAL_FLOW_PRESET_FAST, 1),
    "medium": (cv2.DISOPTICAL_FLOW_PRESET_MEDIUM, 1),
}


class DISFlow:
    """DIS optical flow on grey frames.

    Args:
        preset: ``"ultrafast"``, ``"fast"`` (default: about 6 ms per 480×270 pair,
            refined to half the working size; see ``PRESETS``) or ``"medium"``.
    """

    name = "dis"

    def __init__(self, preset: str = "fast") -> None:
        if preset not in PRESETS:
            raise ValueError(f"DIS preset must be one of {sorted(PRESETS)}, got {preset!r}")
        self.preset = preset
        opencv_preset, finest = PRESETS[preset]
        self._dis = cv2.DISOpticalFlow_create(opencv_preset)
        self._dis.setFinestScale(finest)

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
