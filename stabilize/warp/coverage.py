"""The zoom that hides every border: whether the output frame lies inside the warped
input, and the smallest zoom for which it does.

A zoom z hides the borders of frame t when every output border pixel maps back inside
the input frame (:mod:`stabilize.warp.sources`); the zoom is found by bisection, for all
frames at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stabilize.warp.homography import inverses, zoomed
from stabilize.warp.lens import Lens
from stabilize.warp.sources import homography_sources, lens_sources

BORDER_SAMPLES = 16  # points per edge checked for coverage
MIDDLE_STEP_PX = 4.0  # half the span of the differences that give the warp's Jacobian
ZOOM_STEPS = 16  # bisection steps of the zoom search
# The output's corners among the border points (the ends of the top and bottom edges).
CORNERS = np.array([0, BORDER_SAMPLES - 1, BORDER_SAMPLES, 2 * BORDER_SAMPLES - 1])


def _border(size: tuple[int, int]) -> NDArray:
    h, w = size
    xs = np.linspace(-0.5, w - 0.5, BORDER_SAMPLES)
    ys = np.linspace(-0.5, h - 0.5, BORDER_SAMPLES)
    return np.concatenate(
        [
            np.stack([xs, np.full_like(xs, -0.5)], 1),
            np.stack([xs, np.full_like(xs, h - 0.5)], 1),
            np.stack([np.full_like(ys, -0.5), ys], 1),
            np.stack([np.full_like(ys, w - 0.5), ys], 1),
        ]
    )


@dataclass(frozen=True)
class Framing:
    """The frame a warp reads from: its pinhole camera ``K`` at ``size`` (H, W); under a
    rolling shutter, the knot ``rows`` its per-row corrections are given at; with a
    fisheye ``lens``, the lens the border is mapped through instead of a homography.

    Corrections C are (N, 3, 3), or (N, B, 3, 3) at the knot rows; zooms (N,).
    """

    K: NDArray
    size: tuple[int, int]
    rows: NDArray | None = None
    lens: Lens | None = None

    def border_sources(self, C: NDArray, zoom: NDArray) -> NDArray[np.float64]:
        """Input pixels (N, M, 2) of the output border's M points, for N frames at once."""
        return self.sources(C, zoom, _border(self.size))

    def middle_jacobian(self, C: NDArray, zoom: NDArray) -> NDArray[np.float64]:
        """The Jacobian (N, 2, 2) of each frame's map from output to input pixels at the
        output's middle (central differences, ``MIDDLE_STEP_PX`` either side).

        Its σ_min/σ_max is the stretch a registration of the output against its original
        reads as distortion there. A turn by θ about an axis in the image plane alone
        foreshortens the frame by cos θ across that axis; a 2-D shift after it, back by
        f tan θ, keeps that; a rolling shutter's correction adds its shear and stretch."""
        h, w = self.size
        mid, d = np.array([(w - 1) / 2, (h - 1) / 2]), MIDDLE_STEP_PX
        pts = mid + np.array([[d, 0.0], [-d, 0.0], [0.0, d], [0.0, -d]])
        src = self.sources(C, zoom, pts)
        return np.stack([src[:, 0] - src[:, 1], src[:, 2] - src[:, 3]], axis=-1) / (2 * d)

    def sources(self, C: NDArray, zoom: NDArray, pts: NDArray) -> NDArray[np.float64]:
        """Input pixels (N, M, 2) of output pixels ``pts`` (M, 2), for N frames at once."""
        C = np.asarray(C, dtype=np.float64)
        zoom = np.asarray(zoom, dtype=np.float64)
        if self.lens is not None:
            return lens_sources(self.lens, C, zoom, pts, self.rows)
        Z = zoomed(self.K, zoom)
        Zp = Z[:, None] if C.ndim == 4 else Z
        return homography_sources(inverses(Zp @ C @ np.linalg.inv(self.K)), pts, self.rows)

    def covered(self, C: NDArray, zoom: NDArray) -> NDArray[np.bool_]:
        """Whether the output frame at each zoom lies entirely inside the warped input."""
        h, w = self.size
        xy = self.border_sources(C, zoom)
        x, y = xy[..., 0], xy[..., 1]
        with np.errstate(invalid="ignore"):
            inside = (x >= -0.5) & (x <= w - 0.5) & (y >= -0.5) & (y <= h - 0.5)
        return inside.all(axis=1)

    def required_zooms(self, C: NDArray, max_zoom: float = 4.0) -> NDArray[np.float64]:
        """The smallest zoom ≥ 1 with no border in frame, for each frame: a bisection run
        on all of them together (about 1e-5 of zoom in 16 steps); inf where even
        ``max_zoom`` shows a border."""
        C = np.asarray(C, dtype=np.float64)
        lo, hi = np.ones(len(C)), np.full(len(C), float(max_zoom))
        done = self.covered(C, lo)
        hopeless = ~self.covered(C, hi) & ~done
        for _ in range(ZOOM_STEPS):
            mid = 0.5 * (lo + hi)
            fits = self.covered(C, mid)
            hi = np.where(fits, mid, hi)
            lo = np.where(fits, lo, mid)
        return np.where(done, 1.0, np.where(hopeless, np.inf, hi))
