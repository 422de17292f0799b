"""Per-row turns of a rolling-shutter frame, as the warp needs them.

Row y of frame k was captured at its own time; D_k(y) is the camera's turn between the
frame's middle row and row y. The correction of that row is C_k D_k(y)ᵀ. Knot rows carry
exact turns, and the warp interpolates between them (:func:`stabilize.warp.sources.through_rows`).
Where the turns come from (a gyro, or the video) is the caller's business.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

KNOTS = 17  # rows per frame with an exact correction; the warp interpolates in between


@dataclass(frozen=True)
class RollingShutter:
    """D_k(y_b) for every frame k at the knot rows y_b."""

    turns: NDArray[np.float64]  # (N, B, 3, 3) D_k(y_b)
    rows: NDArray[np.float64]  # (B,) the knot rows y_b, input pixels

    def corrections(self, C: NDArray, frames: NDArray | slice = slice(None)) -> NDArray[np.float64]:
        """Per-row corrections C_k D_k(y_b)ᵀ (N, B, 3, 3) of the ``frames``' corrections
        C (N, 3, 3)."""
        return C[:, None] @ np.swapaxes(self.turns[frames], -1, -2)

    def at(self, frames: NDArray, rows: NDArray) -> NDArray[np.float64]:
        """D_k(y) (n, M, 3, 3) of ``frames`` (n,) at input ``rows`` ((M,) or (n, M)),
        linear between the knot rows (the turns between knots are tiny)."""
        rows = np.broadcast_to(rows, (len(frames), np.shape(rows)[-1]))
        k, frac = between_knots(self.rows, rows)
        below = self.turns[frames[:, None], k]
        return below + frac[..., None, None] * (self.turns[frames[:, None], k + 1] - below)


def between_knots(knots: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    """For rows ``y`` (any shape; clipped to the knots' span), the index k of the knot at
    or above each and the fraction of the way to knot k + 1."""
    y = np.clip(y, knots[0], knots[-1])
    k = np.clip(np.searchsorted(knots, y) - 1, 0, len(knots) - 2)
    return k, (y - knots[k]) / (knots[k + 1] - knots[k])
