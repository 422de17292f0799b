"""The camera path: smoothing on SO(3), the zoom budget, and the choice of zoom."""

from stabilize.path.plan import plan_path
from stabilize.path.smoothing import METHODS, orientations_from_rotations, smooth_orientations
from stabilize.path.zoom import CROP_MODES, choose_zoom

__all__ = [
    "CROP_MODES",
    "METHODS",
    "choose_zoom",
    "orientations_from_rotations",
    "plan_path",
    "smooth_orientations",
]
