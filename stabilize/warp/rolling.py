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
