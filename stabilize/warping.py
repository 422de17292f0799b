"""Correction homographies, the zoom that hides every border, and the warp itself.

For raw orientation O_t and smoothed S_t, the correction C_t = S_t O_tᵀ turns frame t's
rays into the smoothed camera's. Output pixels are then

    p_out ~ K' C_t K⁻¹ p_in,      K' = K with the focal length times the zoom z

(about the principal point). A zoom z hides the borders of frame t when every output
border pixel maps back inside the input frame.

Under a rolling shutter each input row y was captured at its own time, so the correction
depends on the row: C_t(y) = C_t D(y)ᵀ, with D(y) the camera's turn between the frame's
middle row and row y. A frame's warp is then a stack of homographies H(y_b) at knot rows
y_b, interpolated in between. An output pixel's source row is itself unknown, so it is
found by a fixed-point iteration: y ← row of H(y)⁻¹ p_out, starting from the middle.
"""

from __future__ import annotations

import functools

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.lens import Lens, project, unproject

BORDER_SAMPLES = 16  # points per edge checked for coverage
ZOOM_STEPS = 16  # bisection steps of the zoom search
ROW_ITERATIONS = 2  # fixed-point steps for an output pixel's source row
MAP_STEP = 8  # output pixels between exactly computed points of a rolling-shutter map


def zoomed(K: NDArray, zoom: float | NDArray) -> NDArray:
    """K with the focal length times the zoom (a stack of them for an array of zooms)."""
    zoom = np.asarray(zoom, dtype=np.float64)
    out = np.broadcast_to(np.asarray(K, dtype=np.float64), (*zoom.shape, 3, 3)).copy()
    out[..., 0, 0] *= zoom
    out[..., 1, 1] *= zoom
    return out


def homography(K: NDArray, C: NDArray, zoom: float = 1.0) -> NDArray[np.float64]:
    """Input pixels → output pixels: K' C K⁻¹ (for one C, or a stack of them)."""
    H = zoomed(K, zoom) @ C @ np.linalg.inv(K)
    return H / H[..., 2:, 2:]


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


def inverses(H: NDArray) -> NDArray[np.float64]:
    """Inverse homographies, scaled to H[2, 2] = 1 so that they interpolate."""
    Hinv = np.linalg.inv(H)
    return Hinv / Hinv[..., 2:, 2:]


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

    return _through_rows(Hinv, rows, apply)


def lens_sources(
    lens: Lens, C: NDArray, zoom: NDArray, pts: NDArray, rows: NDArray | None = None
) -> NDArray[np.float64]:
    """Input pixels (N, M, 2) of output pixels ``pts`` (M, 2) through a lens: unproject
    with the lens at f·zoom, turn by Cᵀ, project with the lens. ``C`` (N, 3, 3), or
    (N, B, 3, 3) at knot ``rows``; NaN outside the lens's reach."""
    C = np.asarray(C, dtype=np.float64)
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

    return _through_rows(C, rows, apply)


def _through_rows(stack: NDArray, rows: NDArray | None, apply) -> NDArray:
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


def border_sources(
    K: NDArray,
    C: NDArray,
    zoom: NDArray,
    size: tuple[int, int],
    rows: NDArray | None = None,
    lens: Lens | None = None,
) -> NDArray[np.float64]:
    """Input pixels (N, M, 2) of the output border's M points, for N frames at once:
    corrections C (N, 3, 3), or (N, B, 3, 3) at knot ``rows``, zooms (N,)."""
    C = np.asarray(C, dtype=np.float64)
    zoom = np.asarray(zoom, dtype=np.float64)
    pts = _border(size)
    if lens is not None:
        return lens_sources(lens, C, zoom, pts, rows)
    Z = zoomed(K, zoom)
    Zp = Z[:, None] if C.ndim == 4 else Z
    return homography_sources(inverses(Zp @ C @ np.linalg.inv(K)), pts, rows)


def covers(
    K: NDArray,
    C: NDArray,
    zoom: float,
    size: tuple[int, int],
    rows: NDArray | None = None,
    lens: Lens | None = None,
) -> bool:
    """Whether the output frame at ``zoom`` lies entirely inside the warped input.

    ``C`` is one correction, or one per knot row in ``rows`` (rolling shutter); with a
    ``lens`` the border is mapped through it instead of a homography.
    """
    return bool(frames_covered(K, np.asarray(C)[None], np.array([zoom]), size, rows, lens)[0])


def frames_covered(
    K: NDArray,
    C: NDArray,
    zoom: NDArray,
    size: tuple[int, int],
    rows: NDArray | None = None,
    lens: Lens | None = None,
) -> NDArray[np.bool_]:
    """:func:`covers` for N frames at once: corrections C (N, 3, 3), or (N, B, 3, 3) at
    knot ``rows``, zooms (N,)."""
    h, w = size
    xy = border_sources(K, C, zoom, size, rows, lens)
    x, y = xy[..., 0], xy[..., 1]
    with np.errstate(invalid="ignore"):
        inside = (x >= -0.5) & (x <= w - 0.5) & (y >= -0.5) & (y <= h - 0.5)
    return inside.all(axis=1)


def required_zoom(
    K: NDArray,
    C: NDArray,
    size: tuple[int, int],
    max_zoom: float = 4.0,
    rows: NDArray | None = None,
    lens: Lens | None = None,
) -> float:
    """The smallest zoom ≥ 1 with no border in frame (bisection); inf if above max_zoom."""
    return float(required_zooms(K, np.asarray(C)[None], size, max_zoom, rows, lens)[0])


def required_zooms(
    K: NDArray,
    C: NDArray,
    size: tuple[int, int],
    max_zoom: float = 4.0,
    rows: NDArray | None = None,
    lens: Lens | None = None,
) -> NDArray[np.float64]:
    """:func:`required_zoom` of N frames' corrections at once: the bisection runs on all
    of them together (about 1e-5 of zoom in 16 steps)."""
    C = np.asarray(C, dtype=np.float64)

    def covered(zoom: NDArray) -> NDArray[np.bool_]:
        return frames_covered(K, C, zoom, size, rows, lens)

    lo, hi = np.ones(len(C)), np.full(len(C), float(max_zoom))
    done = covered(lo)
    hopeless = ~covered(hi) & ~done
    for _ in range(ZOOM_STEPS):
        mid = 0.5 * (lo + hi)
        fits = covered(mid)
        hi = np.where(fits, mid, hi)
        lo = np.where(fits, lo, mid)
    return np.where(done, 1.0, np.where(hopeless, np.inf, hi))


def resize_image(image: NDArray, size: tuple[int, int]) -> NDArray:
    """An image (or one plane) at (H, W): area averaging to shrink, bilinear to grow."""
    h, w = size
    shrink = h * w < image.shape[0] * image.shape[1]
    return cv2.resize(image, (w, h), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)


def warp_frame(frame: NDArray[np.uint8], H: NDArray) -> NDArray[np.uint8]:
    """cv2.warpPerspective (about 10 ms per 1080p frame on this CPU), black outside."""
    h, w = frame.shape[:2]
    return cv2.warpPerspective(
        frame, H, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT
    )


def warp_frame_rolling(frame: NDArray[np.uint8], H: NDArray, rows: NDArray) -> NDArray[np.uint8]:
    """Warp by row-dependent homographies H (B, 3, 3) at input knot rows (B,)."""
    return remap_from(frame, rolling_source(H, rows))


def rolling_source(H: NDArray, rows: NDArray):
    """The map output pixels (M, 2) → input pixels of row-dependent homographies."""
    Hinv = inverses(H)[None]
    return lambda pts: homography_sources(Hinv, pts, rows)[0]


def lens_source(lens: Lens, C: NDArray, zoom: float, rows: NDArray | None = None):
    """The map output pixels (M, 2) → input pixels of one frame through a lens."""
    C, zoom = np.asarray(C)[None], np.array([zoom])
    return lambda pts: lens_sources(lens, C, zoom, pts, rows)[0]


def warp_frame_lens(
    frame: NDArray[np.uint8], lens: Lens, C: NDArray, zoom: float, rows: NDArray | None = None
) -> NDArray[np.uint8]:
    """Undistort → rotate → redistort in one remap (see :mod:`stabilize.lens`)."""
    return remap_from(frame, lens_source(lens, C, zoom, rows))


def remap_from(frame: NDArray[np.uint8], source, fill: int = 0) -> NDArray[np.uint8]:
    """Warp a frame by any smooth map ``source``: output pixels (M, 2) → input pixels.

    The map is computed exactly on a grid every ``MAP_STEP`` output pixels, corners
    included, and interpolated bilinearly in between (about 0.01 px off); NaN marks
    pixels with no source. ``cv2.remap`` then samples the frame.
    """
    h, w = frame.shape[:2]
    (xs, Wx), (ys, Wy) = _knots(w), _knots(h)
    gx, gy = np.meshgrid(xs, ys)
    coarse = np.nan_to_num(source(np.c_[gx.ravel(), gy.ravel()]), nan=-1e4)
    coarse = coarse.reshape(*gx.shape, 2)
    # Bilinear upsampling as two small matrix products, in float: cv2.resize cannot keep
    # the corners aligned and cv2.remap would quantise the weights to 1/32 of a cell.
    maps = [Wy @ coarse[..., c].astype(np.float32) @ Wx.T for c in range(2)]
    return cv2.remap(
        frame, maps[0], maps[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=fill
    )


@functools.lru_cache(maxsize=8)
def _knots(n: int) -> tuple[NDArray, NDArray]:
    """Knot positions every ~MAP_STEP pixels over 0..n-1 (both ends included), and the
    (n, knots) matrix of linear-interpolation weights from knots to pixels."""
    count = (n - 1) // MAP_STEP + 2
    knots = np.linspace(0.0, n - 1.0, count)
    u = np.arange(n) * ((count - 1) / max(n - 1, 1))
    before = np.minimum(u.astype(np.intp), count - 2)
    frac = u - before
    weights = np.zeros((n, count), np.float32)
    weights[np.arange(n), before] = 1.0 - frac
    weights[np.arange(n), before + 1] = frac
    return knots, weights


def warp_frames_torch(
    frames: NDArray[np.uint8], H: NDArray, device: str = "cuda", fill: int = 0
) -> NDArray[np.uint8]:
    """Warp a batch (B, H, W) or (B, H, W, C) by homographies (B, 3, 3) with kornia on
    ``device``, ``fill`` outside.

    The same mapping as :func:`warp_frame` (pixel centres at integers, bilinear), for
    CUDA, where one batched call beats a frame at a time. On the CPU, OpenCV is about 20×
    faster than this.
    """
    import kornia
    import torch

    planar = frames.ndim == 3
    src = torch.from_numpy(np.ascontiguousarray(frames)).to(device)
    src = (src[:, None] if planar else src.permute(0, 3, 1, 2)).float() - fill
    M = torch.as_tensor(np.asarray(H), dtype=torch.float32, device=device)
    h, w = frames.shape[1:3]
    # Warping (x - fill) with zero padding, then adding fill back, pads with fill.
    out = kornia.geometry.transform.warp_perspective(src, M, (h, w), align_corners=True)
    out = (out + fill).round_().clamp_(0, 255).to(torch.uint8)
    out = out[:, 0] if planar else out.permute(0, 2, 3, 1)
    return out.cpu().numpy()
