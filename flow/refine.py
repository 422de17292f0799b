"""Flow vectors refined at chosen points: Lucas–Kanade, started from a dense flow's.

DIS's ``fast`` preset is refined only down to half the working size (:mod:`flow.dis`),
so its vectors carry errors of a tenth of a pixel that neighbouring vectors share. For
what a rotation leaves of a pair (a fraction of a pixel a frame: the 2-D similarity of
:mod:`stabilize.motion.residual`), that error is all there is on a scene the rotation
explains: on a rendered 45° distant scene the similarity's zoom read high-passed steps of
0.077 px (at the 480 px flow's side) from DIS's vectors, the same after the true
rotations as after the estimated ones; refined here, 0.035 (DIS itself refined to the
full working size: 0.043, at four times the flow's time).

Each point is tracked from ``p`` to ``p + d`` by iterating the Lucas–Kanade step over a
square window W (OpenCV's ``calcOpticalFlowPyrLK``, on the finest level alone),

    d ← d + G⁻¹ Σ_W ∇I₀ (I₀(q) − I₁(q + d)),   G = Σ_W ∇I₀ ∇I₀ᵀ,

from the flow's own vector: it converges within the window's pull, where the flow put it
already. A point it loses (too little texture, the window leaving the frame), or that it
moves further than ``MAX_MOVE_PX`` from where the flow put it (a wrong minimum), keeps the
flow's vector.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from flow.base import to_grey

WINDOW_PX = 21  # the window's side: 15, 21 and 31 px read the zoom's steps 0.035-0.037
MAX_MOVE_PX = 2.0  # px: a refinement further from the flow's vector found another minimum
ITERATIONS = 20
EPSILON_PX = 0.01  # stop once a step moves the point less than this


def refine_at(
    frame0: NDArray[np.uint8],
    frame1: NDArray[np.uint8],
    x: NDArray,
    y: NDArray,
    u: NDArray,
    v: NDArray,
    window: int = WINDOW_PX,
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """The flow (u, v) (M,) at pixel positions (x, y) (M,) (columns and rows of the
    frames) refined by Lucas–Kanade between ``frame0`` and ``frame1`` (grey or RGB, the
    flow's size); where it fails or moves a vector over ``MAX_MOVE_PX``, the vector as
    given. Non-finite vectors stay as they are."""
    grey0, grey1 = to_grey(frame0), to_grey(frame1)
    u = np.asarray(u, np.float32)
    v = np.asarray(v, np.float32)
    points = np.stack([np.asarray(x, np.float32), np.asarray(y, np.float32)], 1)
    finite = np.isfinite(u) & np.isfinite(v)
    if not finite.any():  # (OpenCV refuses an empty set of points)
        return u, v
    guess = points + np.stack([np.where(finite, u, 0), np.where(finite, v, 0)], 1)
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, ITERATIONS, EPSILON_PX)
    found, status, _ = cv2.calcOpticalFlowPyrLK(
        grey0,
        grey1,
        points[:, None],
        guess[:, None].copy(),
        winSize=(window, window),
        maxLevel=0,
        criteria=criteria,
        flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
    )
    moved = found[:, 0] - guess
    kept = (
        finite
        & (status[:, 0] == 1)
        & np.isfinite(moved).all(axis=1)
        & (np.abs(moved).max(axis=1) <= MAX_MOVE_PX)
    )
    refined = found[:, 0] - points
    return np.where(kept, refined[:, 0], u), np.where(kept, refined[:, 1], v)
