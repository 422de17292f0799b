"""What the output shows where a frame has no source (``--border``).

A crop that hides every border (``--crop auto`` or ``dynamic``) shows none of it; with
``--crop none`` the frame's moving edge is in view. ``black`` shows black there (in the
frame's range), ``edge`` repeats the frame's edge pixels outwards and ``mirror`` reflects
the frame about its edge pixels' centres, as Gyroflow's background modes and most
editors' offer, so that the full frame is kept without a black band that jumps.
"""

from __future__ import annotations

import cv2

# name → (OpenCV's border mode, torch grid_sample's padding mode). OpenCV's REFLECT_101
# reflects about the edge pixel's centre (-1 → 1), as grid_sample's "reflection" does
# with align_corners=True, so a frame warped on CUDA matches the CPU's.
BORDERS: dict[str, tuple[int, str]] = {
    "black": (cv2.BORDER_CONSTANT, "zeros"),
    "edge": (cv2.BORDER_REPLICATE, "border"),
    "mirror": (cv2.BORDER_REFLECT_101, "reflection"),
}


def opencv_border(name: str) -> int:
    """OpenCV's border mode for ``--border`` ``name``."""
    return BORDERS[name][0]


def torch_padding(name: str) -> str:
    """torch grid_sample's (and kornia's) padding mode for ``--border`` ``name``."""
    return BORDERS[name][1]
