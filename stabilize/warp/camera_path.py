"""The planned camera path of a clip, and how each of its frames is warped.

A frame is warped by one homography, unless it must be warped by a map: through a lens
profile, or row by row under a rolling shutter. On CUDA the warps of a batch run
together: homographies with kornia, maps with torch's grid_sample (their knots are
computed on the CPU, a few thousand points a frame).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stabilize.video import i420
from stabilize.warp.cuda import remap_frames_torch, warp_frames_torch
from stabilize.warp.frames import warp_frame
from stabilize.warp.homography import homography
from stabilize.warp.lens import Lens
from stabilize.warp.planes import chroma_homography, remap_planes, warp_planes
from stabilize.warp.remap import coarse_map, remap_from
from stabilize.warp.sources import SourceMap, lens_source, rolling_source


@dataclass
class CameraPath:
    """The estimated and the planned camera path of a clip."""

    times: NDArray  # (N,) s
    rotations: NDArray  # (N-1, 3, 3) R_t
    support: NDArray  # (N-1,)
    raw: NDArray  # (N, 3, 3) O_t
    smooth: NDArray  # (N, 3, 3) S_t
    zoom: NDArray  # (N,) applied zoom
    homographies: NDArray  # (N, 3, 3) input → output pixels (the middle row's)
    K: NDArray  # (3, 3), or each frame's (N, 3, 3): an edited clip's shots of two cameras
    # Rolling shutter: the corrections of each knot row (N, B, 3, 3) at input rows (B,).
    row_corrections: NDArray | None = None
    knot_rows: NDArray | None = None
    lens: Lens | None = None  # fisheye: frames are warped through it, not by homographies
    # (N, 3, 3) the 2-D correction D_t after the rotation (normalised coordinates; the
    # homographies and the row corrections include it)
    shift: NDArray | None = None
    # How the path was planned (stabilize.path.plan): "optimal" (the steadiest path within
    # the crop), "smoothed" (kept as smoothed: held by --lock, or within the budget where
    # that programme found no answer), "bent" (over the budget where it found none, so
    # bent towards the raw one) or "uncropped"
    planner: str = "smoothed"
    # The first frame of each shot, each planned on its own (stabilize.motion.cuts.shots):
    # an edited clip's cuts
    shots: tuple[int, ...] = (0,)

    def corrections(self, frames: int | slice | NDArray = slice(None)) -> NDArray:
        """C_t (3, 3) of frame t's middle row, or a stack of them (every frame's by
        default): D_t S_t O_tᵀ, the turn to the planned orientation, then the 2-D
        correction."""
        C = self.smooth[frames] @ np.swapaxes(self.raw[frames], -1, -2)
        return C if self.shift is None else self.shift[frames] @ C

    @property
    def plain(self) -> bool:
        """Whether every frame is warped by its homography alone (no lens, no rows)."""
        return self.lens is None and self.row_corrections is None

    def warp_many(
        self,
        batch: Sequence[tuple[int, NDArray[np.uint8]]],
        device: str = "cpu",
        full_range: bool = False,
        border: str = "black",
    ) -> list[NDArray[np.uint8]]:
        """Output frames of (k, frame) pairs, RGB or I420 (2-D; ``full_range``: its
        black), ``border`` where they have no source (:mod:`stabilize.warp.border`); on
        CUDA the batch is warped together (by homographies, or by the lens's or the rows'
        maps)."""
        eight_bit = all(frame.dtype == np.uint8 for _, frame in batch)
        if not (device.startswith("cuda") and eight_bit):
            return [self.warp(k, frame, full_range, border) for k, frame in batch]
        return self.warp_together(batch, device, full_range, border)

    def warp_together(
        self,
        batch: Sequence[tuple[int, NDArray[np.uint8]]],
        device: str,
        full_range: bool = False,
        border: str = "black",
    ) -> list[NDArray[np.uint8]]:
        """8-bit (k, frame) pairs warped as one batch with torch on ``device``."""
        frames = np.stack([frame for _, frame in batch])
        ks = [k for k, _ in batch]
        if self.plain:
            H = self.homographies[ks]
            Hc = np.array([chroma_homography(h) for h in H])

            def warp(frames: NDArray, plane: int, fill: int) -> NDArray:
                return warp_frames_torch(frames, Hc if plane else H, device, fill, border)
        else:
            h, w = frames.shape[1:3]
            size = (h * 2 // 3, w) if frames.ndim == 3 else (h, w)  # I420: the luma's
            coarse = np.stack([coarse_map(self.source(k), size) for k in ks])

            def warp(frames: NDArray, plane: int, fill: int) -> NDArray:
                return remap_frames_torch(frames, coarse, device, fill, plane > 0, border)

        if frames.ndim == 4:
            return list(warp(frames, 0, 0))
        planes = [np.stack(p) for p in zip(*(i420.split(f) for f in frames), strict=True)]
        fills = i420.black(frames, full_range)
        warped = [warp(p, i, fill) for i, (p, fill) in enumerate(zip(planes, fills, strict=True))]
        return [i420.join(*parts) for parts in zip(*warped, strict=True)]

    def source(self, k: int) -> SourceMap:
        """Frame k's map from output to input pixels, through the lens or row by row."""
        rolling = self.row_corrections is not None
        C = self.row_corrections[k] if rolling else self.corrections(k)
        if self.lens is not None:
            return lens_source(self.lens, C, self.zoom[k], self.knot_rows)
        K = self.K[k] if self.K.ndim == 3 else self.K
        return rolling_source(homography(K, C, self.zoom[k]), self.knot_rows)

    def warp(
        self, k: int, frame: NDArray[np.uint8], full_range: bool = False, border: str = "black"
    ) -> NDArray[np.uint8]:
        """Frame k of the output, from frame k of the input (RGB, or I420 when 2-D, whose
        black depends on its range), ``border`` where it has no source."""
        planar = frame.ndim == 2
        if self.plain:
            H = self.homographies[k]
            if planar:
                return warp_planes(frame, H, full_range, border)
            return warp_frame(frame, H, border)
        source = self.source(k)
        if planar:
            return remap_planes(frame, source, full_range, border)
        return remap_from(frame, source, border=border)
