"""The one result type every rotation estimator returns."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rotation.so3 import log_so3


@dataclass(frozen=True)
class RotationEstimate:
    """Relative camera rotation of one frame pair.

    Attributes:
        matrix: R_t (3×3, float64) with p_{t+1} ~ K R_t K⁻¹ p_t for static points at
            infinity (CONVENTIONS.md).
        rotvec: rotation vector of R_t, radians.
        support: share of the valid sampled flow vectors that agree with the answer
            (for the Hough estimator, whose compatible-rotation line passes through the
            winning bin), 0..1.
        inliers: bool mask over the sampled grid (ny, nx) of those vectors.
    """

    matrix: NDArray[np.float64]
    rotvec: NDArray[np.float64]
    support: float
    inliers: NDArray[np.bool_]

    @classmethod
    def from_matrix(
        cls, matrix: NDArray[np.float64], support: float, inliers: NDArray[np.bool_]
    ) -> RotationEstimate:
        matrix = np.asarray(matrix, dtype=np.float64)
        return cls(matrix, log_so3(matrix), float(support), np.asarray(inliers, dtype=bool))

    @property
    def angle_deg(self) -> float:
        """Rotation angle of R_t in degrees."""
        return float(np.degrees(np.linalg.norm(self.rotvec)))
