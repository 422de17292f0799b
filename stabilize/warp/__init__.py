"""Warping frames along the planned path: correction homographies, lens profiles,
rolling-shutter maps, the zoom that hides every border, and pass 2 itself."""

from stabilize.warp.camera_path import CameraPath
from stabilize.warp.homography import homography
from stabilize.warp.lens import Lens, LensError, read_lens_profile

__all__ = ["CameraPath", "Lens", "LensError", "homography", "read_lens_profile"]
