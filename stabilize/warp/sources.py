"""Where each output pixel comes from: maps output pixels → input pixels, through a
homography or a lens, and under a rolling shutter row by row.

Under a rolling shutter each input row y was captured at its own time, so the correction
depends on the row: C_t(y) = C_t D(y)ᵀ, with D(y) the camera's turn between the frame's
middle row and row y. A frame's warp is then a stack of homographies H(y_b) at knot rows
y_b, interpolated in between. An output pixel's source row is itself unknown, so it is
found by a fixed-point iteration: y ← row of H(y)⁻¹ p_out, starting from the middle.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from stabilize.warp.homography import inverses
from stabilize.warp.lens import Lens, project, unproject

ROW_ITERATIONS = 2  # fixed-point steps for an output pixel's source row

# A map from output pixels (M, 2) to input pixels (M, 2), NaN where there is no source.
SourceMap = Callable[[NDArray], NDArray]


def homography_sources(
    Hinv: NDArray, pts: NDArray, rows: NDArray | None = None
) -> NDArray[np.float64]:
    """Input pixels (N, M, 2) of output pixels ``pts`` (M, 2) for N frames' inverse
    homographies (N, 3, 3), or (N, B, 3, 3) at knot ``rows`` (rolling shutter; scaled
    as by :func:`inverses`, so that they interpolate). NaN behind the camera."""
    ph = np.c_[pts, np.ones(len(pts))]

    def apply(H: NDArray) -> NDArray:
        # matmul, not einsum: numpy's einsum does not reach BLAS here (10× slower)
        q = (H @ ph[:, :, None])[..., 0] if H.ndim == 4 else ph @ np.swapaxes(H, -1, -2)
        z = np.where(q[..., 2] > 1e-12, q[..., 2], np.nan)
        return q[..., :2] / z[..., None]

    return through_rows(Hinv, rows, apply)


def lens_sources(
    lens: Lens, C: NDArray, zoom: NDArray, pts: NDArray, rows: NDArray | None = None
) -> NDArray[np.float64]:
    """Input pixels (N, M, 2) of output pixels ``pts`` (M, 2) through a lens: unproject
    with the lens at f·zoom, map by C⁻¹ (Cᵀ for a pure turn; C may carry a 2-D
    correction too), project with the lens. ``C`` (N, 3, 3), or (N, B, 3, 3) at knot
    ``rows``; NaN outside the lens's reach."""
    C = np.swapaxes(np.linalg.inv(np.asarray(C, dtype=np.float64)), -1, -2)
    zoom = np.asarray(zoom, dtype=np.float64)
    n, m = len(C), len(pts)
    c = lens.K[:2, 2]
    scaled = c + (pts[None] - c) / zoom[:, None, None]  # the zoomed lens's unprojection
    rays = unproject(lens, scaled.reshape(-1, 2)).reshape(n, m, 3)

    def apply(Cp: NDArray) -> NDArray:
        # Row vectors times C (one per frame, or per point): matmul, as in
        # homography_sources, since einsum does not reach BLAS here.
        turned = (rays[..., None, :] @ Cp)[..., 0, :] if Cp.ndim == 4 else rays @ Cp
        return project(lens, turned.reshape(-1, 3)).reshape(n, m, 2)

    return through_rows(C, rows, apply)


def through_rows(stack: NDArray, rows: NDArray | None, apply) -> NDArray:
    """``apply`` per frame (N, 3, 3); with knot ``rows``, the source row of every point
    is found by fixed-point iteration from the middle knot, the stack (N, B, 3, 3)
    interpolated per point (N, M, 3, 3). Between knots the turns are tiny, so
    interpolating the matrices linearly is exact enough."""
    if rows is None:
        return apply(stack)
    src = apply(stack[:, len(rows) // 2])
    frame = np.arange(len(stack))[:, None]
    for _ in range(ROW_ITERATIONS):
        y = np.clip(np.nan_to_num(src[..., 1], nan=rows[0]), rows[0], rows[-1])
        k = np.clip(np.searchsorted(rows, y) - 1, 0, len(rows) - 2)
        frac = ((y - rows[k]) / (rows[k + 1] - rows[k]))[..., None, None]
        src = apply(stack[frame, k] + frac * (stack[frame, k + 1] - stack[frame, k]))
    return src


def rolling_source(H: NDArray, rows: NDArray):
    """The map output pixels (M, 2) → input pixels of row-dependent homographies."""
    Hinv = inverses(H)[None]
    return lambda pts: homography_sources(Hinv, pts, rows)[0]


def lens_source(lens: Lens, C: NDArray, zoom: float, rows: NDArray | None = None):
    """The map output pixels (M, 2) → input pixels of one frame through a lens."""
    C, zoom = np.asarray(C)[None], np.array([zoom])
    return lambda pts: lens_sources(lens, C, zoom, pts, rows)[0]
