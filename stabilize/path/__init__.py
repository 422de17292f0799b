"""The camera path: smoothing on SO(3), the zoom budget, and the choice of zoom.

The names below load when first used, so the command line can read the registries of
methods and crop modes without loading the planner (and its warps).
"""

from __future__ import annotations

from stabilize.lazy import lazy_exports

_EXPORTS = {
    "CROP_MODES": "stabilize.path.zoom",
    "METHODS": "stabilize.path.smoothing",
    "choose_zoom": "stabilize.path.zoom",
    "orientations_from_rotations": "stabilize.path.smoothing",
    "plan_path": "stabilize.path.plan",
    "smooth_orientations": "stabilize.path.smoothing",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports("stabilize.path", _EXPORTS)
