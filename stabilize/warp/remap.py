"""Warping a frame by any smooth map, in one ``cv2.remap``."""

from __future__ import annotations

import functools

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.warp.sources import SourceMap

MAP_STEP = 8  # output pixels between exactly computed points of a map


def remap_from(frame: NDArray[np.uint8], source: SourceMap, fill: int = 0) -> NDArray[np.uint8]:
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
