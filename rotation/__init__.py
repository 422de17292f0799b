"""Robust frame-to-frame camera rotation from optical flow (no video involved).

Conventions (axes, flow layout, R_t) are those of CONVENTIONS.md:
p_{t+1} ~ K R_t K⁻¹ p_t for static points at infinity.

>>> from rotation import HoughEstimator, estimate, RotationEstimate

The estimator (numba kernels) loads when first used, so ``rotation.so3`` and
``rotation.camera`` stay cheap to import.
"""

import importlib

from rotation.cache import use_cache_dir, use_plain_messages

use_cache_dir()  # before any kernel is defined: cached in the user's folder
use_plain_messages()  # and numba's messages leave sys.stdout and sys.stderr alone

from rotation import camera, so3  # noqa: E402

_EXPORTS = {
    "HoughEstimator": "rotation.hough",
    "estimate": "rotation.hough",
    "RotationEstimate": "rotation.result",
}
__all__ = ["HoughEstimator", "RotationEstimate", "baselines", "camera", "estimate", "so3"]


def __getattr__(name: str):
    if name == "baselines":
        return importlib.import_module("rotation.baselines")
    if name not in _EXPORTS:
        raise AttributeError(f"module 'rotation' has no attribute {name!r}")
    return getattr(importlib.import_module(_EXPORTS[name]), name)
