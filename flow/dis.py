"""OpenCV's Dense Inverse Search flow (Kroeger et al. 2016): the fast CPU default."""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor

import cv2
import numpy as np
from numpy.typing import NDArray

from flow.base import check_frame, check_pair, to_grey
from flow.grain import noise_level, through_grain

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
        self._dis = self._create()
        self._local = threading.local()  # an instance per thread: they hold scratch state

    def __call__(self, frame0: NDArray, frame1: NDArray) -> NDArray[np.float32]:
        grey0, grey1 = (to_grey(frame) for frame in check_pair(frame0, frame1))
        pair = through_grain(grey0, grey1, noise_level(grey0), noise_level(grey1))
        return self._flow(self._dis, *pair)

    def many(self, frames: Iterable[NDArray]) -> Iterator[NDArray[np.float32]]:
        """The flows of consecutive pairs, in order, several pairs computed at once.

        OpenCV splits one pair's search into stripes over its threads; here each of
        those threads takes a whole pair instead, with OpenCV's own threading off while
        the frames come. On 2 cores (1080p, 10 s, pass 1 with its votes beside it) that
        took 3.2–3.3 s instead of 3.9, the flows identical to the bit.
        """
        threads = cv2.getNumThreads()  # handed back as found
        workers = max(1, threads)
        pending: deque = deque()
        previous, previous_noise = None, None
        cv2.setNumThreads(1)
        try:
            with ThreadPoolExecutor(workers, thread_name_prefix="dis") as pool:
                for frame in frames:
                    grey = to_grey(check_frame(frame))
                    noise = pool.submit(noise_level, grey)  # each frame's once (flow.grain)
                    if previous is not None:
                        if grey.shape != previous.shape:
                            raise ValueError(
                                f"frame sizes differ: {previous.shape[::-1]} and {grey.shape[::-1]}"
                            )
                        pair = (previous, grey, previous_noise, noise)
                        pending.append(pool.submit(self._flow_here, *pair))
                        if len(pending) > 2 * workers:
                            yield pending.popleft().result()
                    previous, previous_noise = grey, noise
                while pending:
                    yield pending.popleft().result()
        finally:
            cv2.setNumThreads(threads)

    def _create(self) -> cv2.DISOpticalFlow:
        opencv_preset, finest = PRESETS[self.preset]
        dis = cv2.DISOpticalFlow_create(opencv_preset)
        dis.setFinestScale(finest)
        return dis

    def _flow_here(
        self, grey0: NDArray[np.uint8], grey1: NDArray[np.uint8], noise0: Future, noise1: Future
    ) -> NDArray:
        """The flow, by this thread's own instance, through the pair's grain (its
        frames' noise levels, read on the pool before the pair was queued)."""
        if not hasattr(self._local, "dis"):
            self._local.dis = self._create()
        pair = through_grain(grey0, grey1, noise0.result(), noise1.result())
        return self._flow(self._local.dis, *pair)

    @staticmethod
    def _flow(dis: cv2.DISOpticalFlow, grey0: NDArray, grey1: NDArray) -> NDArray[np.float32]:
        return dis.calc(grey0, grey1, None).astype(np.float32, copy=False)
