"""Planning the camera path: smooth it, keep it within the zoom budget, choose the zoom.

Orientations O_{t+1} = R_t O_t are smoothed on SO(3) into S_t (:mod:`.smoothing`); the
correction C_t = S_t O_tᵀ of each frame needs some zoom to hide the borders
(:mod:`stabilize.warp.coverage`); where it needs more than the budget, the path is bent
(:mod:`.budget`); then the crop mode picks the zoom (:mod:`.zoom`).

With a rolling shutter, each frame's correction also undoes the camera's turn between
its middle row and every other row, C_t(y) = C_t D_t(y)ᵀ.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.path.budget import respect_zoom_budget
from stabilize.path.smoothing import orientations_from_rotations, smooth_orientations
from stabilize.path.zoom import CROP_MODES, choose_zoom
from stabilize.settings import Settings
from stabilize.warp.camera_path import CameraPath
from stabilize.warp.coverage import Framing
from stabilize.warp.homography import homography
from stabilize.warp.lens import Lens
from stabilize.warp.rolling import RollingShutter

LOOSER = 0.35  # the smoothing time constant, as a share, of the path bent towards first


def plan_path(
    times: NDArray,
    rotations: NDArray,
    support: NDArray,
    K: NDArray,
    size: tuple[int, int],
    settings: Settings,
    rolling: RollingShutter | None = None,
    lens: Lens | None = None,
) -> CameraPath:
    """The planned path of frames at ``times`` with rotations R_t (N-1, 3, 3)."""
    if settings.crop not in CROP_MODES:
        raise ValueError(f"crop must be one of {tuple(CROP_MODES)}, got {settings.crop!r}")
    O = orientations_from_rotations(rotations)
    S = smooth_orientations(O, times, settings.smooth, settings.method)
    framing = Framing(K, size, None if rolling is None else rolling.rows, lens)

    def corrections(path: NDArray, frames: NDArray | slice = slice(None)) -> NDArray:
        C = path @ np.swapaxes(O[frames], -1, -2)
        return C if rolling is None else rolling.corrections(C, frames)

    def zoom_of(path: NDArray, frames: NDArray) -> NDArray:
        return framing.required_zooms(corrections(path, frames), settings.max_zoom * 1.001)

    def over(path: NDArray, frames: NDArray) -> NDArray:
        zoom = np.full(len(frames), settings.max_zoom)
        return ~framing.covered(corrections(path, frames), zoom)

    if settings.crop == "none":
        need = np.ones(len(O))
    else:
        # Where the budget binds, first give up only the slow part of the smoothing.
        looser = smooth_orientations(O, times, settings.smooth * LOOSER, settings.method)
        S, need = respect_zoom_budget(
            O, S, times, zoom_of, settings.max_zoom, settings.smooth, via=(looser,), over=over
        )
    zoom = choose_zoom(need, times, settings.crop, settings.max_zoom, settings.smooth)
    C = S @ np.swapaxes(O, -1, -2)
    H = np.array([homography(K, c, z) for c, z in zip(C, zoom, strict=True)])
    if rolling is None:
        return CameraPath(times, rotations, support, O, S, zoom, H, K, lens=lens)
    rows = framing.rows
    return CameraPath(times, rotations, support, O, S, zoom, H, K, corrections(S), rows, lens)
