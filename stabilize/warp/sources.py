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
from stabilize.warp.rolling import between_knots

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

    def finish(q: NDArray) -> NDArray:
        z = np.where(q[..., 2] > 1e-12, q[..., 2], np.nan)
        return q[..., :2] / z[..., None]

    def linear(H: NDArray) -> NDArray:  # H (N, [B,] 3, 3) → (M, N, [B,] 3)
        # Three broadcast products, not BLAS: these are small (10⁶ flops a 1080p frame),
        # and BLAS's threads, fighting the encoder for the cores, took 8 ms a frame.
        col = np.moveaxis(H, -1, 0)  # (3, N, [B,] 3): the columns H[..., :, j]
        p = ph.reshape(len(ph), *([1] * (H.ndim - 2)), 3)
        return p[..., 0:1] * col[0] + p[..., 1:2] * col[1] + p[..., 2:3] * col[2]

    return through_rows(Hinv, rows, linear, finish)


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

    def turn(Cp: NDArray) -> NDArray:  # row vectors times each frame's (and knot's) C
        if Cp.ndim == 4:
            return np.einsum("nmi,nbij->mnbj", rays, Cp)
        return np.swapaxes(rays @ Cp, 0, 1)

    def finish(turned: NDArray) -> NDArray:
        return project(lens, turned.reshape(-1, 3)).reshape(*turned.shape[:-1], 2)

    return through_rows(C, rows, turn, finish)


def through_rows(stack: NDArray, rows: NDArray | None, linear, finish) -> NDArray:
    """The sources (N, M, 2) of M points: ``finish`` (projection to pixels, (..., 3) →
    (..., 2)) of ``linear`` (the points' homogeneous images by each frame's 3×3 matrix,
    points first: (N, [B,] 3, 3) → (M, N, [B,] 3)).

    With knot ``rows`` the stack is (N, B, 3, 3) and a point's matrix is interpolated
    linearly between the knots of its source row, found by fixed-point iteration from
    the middle knot. Between knots the turns are tiny, so interpolating the matrices
    linearly is exact enough; and since ``linear`` is linear, the images by every knot's
    matrix are computed once and interpolated instead (a 1080p frame's map in 5 ms
    rather than 25)."""
    if rows is None:
        return np.swapaxes(finish(linear(stack)), 0, 1)
    images = linear(stack)  # (M, N, B, 3)
    m, n, b = images.shape[:3]
    src = finish(images[:, :, b // 2])
    flat = images.reshape(-1, 3)  # a point's knots are b rows apart: one flat gather
    first = (np.arange(m * n) * b).reshape(m, n)
    for _ in range(ROW_ITERATIONS):
        k, frac = between_knots(rows, np.nan_to_num(src[..., 1], nan=rows[0]))
        below = np.take(flat, first + k, axis=0)
        src = finish(below + frac[..., None] * (np.take(flat, first + k + 1, axis=0) - below))
    return np.swapaxes(src, 0, 1)


def rolling_source(H: NDArray, rows: NDArray):
    """The map output pixels (M, 2) → input pixels of row-dependent homographies."""
    Hinv = inverses(H)[None]
    return lambda pts: homography_sources(Hinv, pts, rows)[0]


def lens_source(lens: Lens, C: NDArray, zoom: float, rows: NDArray | None = None):
    """The map output pixels (M, 2) → input pixels of one frame through a lens."""
    C, zoom = np.asarray(C)[None], np.array([zoom])
    return lambda pts: lens_sources(lens, C, zoom, pts, rows)[0]
