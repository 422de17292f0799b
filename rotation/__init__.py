"""Robust frame-to-frame camera rotation from optical flow (no video involved).

Conventions (axes, flow layout, R_t) are those of CONVENTIONS.md:
p_{t+1} ~ K R_t K⁻¹ p_t for static points at infinity.

>>> from rotation import HoughEstimator, estimate, RotationEstimate
"""

from rotation.cache import use_cache_dir

use_cache_dir()  # before any kernel is defined: cached in the user's folder

from rotation import baselines, camera, so3  # noqa: E402
from rotation.hough import HoughEstimator, estimate  # noqa: E402
from rotation.result import RotationEstimate  # noqa: E402

__all__ = ["HoughEstimator", "RotationEstimate", "baselines", "camera", "estimate", "so3"]
