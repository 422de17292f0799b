"""Warping I420 frames (:mod:`stabilize.video.i420`) plane by plane.

A chroma plane is the luma plane at half size, with pixel centres at integers in both
(CONVENTIONS.md), so full-size x is 2x' + ½ at half size x', and a full-size homography
H acts on chroma as S H S⁻¹ with S: x' = (x + ½)/2 - ½. A full-size map p ↦ m(p) acts
on chroma as p' ↦ S m(S⁻¹ p').
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.video.i420 import black, join, split
from stabilize.warp.border import opencv_border
from stabilize.warp.frames import resize_image
from stabilize.warp.remap import MAP_STEP, coarse_map, dense_map, half_knots, remap_with
from stabilize.warp.sources import SourceMap

HALF = np.array([[0.5, 0.0, -0.25], [0.0, 0.5, -0.25], [0.0, 0.0, 1.0]])  # S above


def chroma_homography(H: NDArray) -> NDArray[np.float64]:
    """The full-size homography H acting on the half-size chroma planes: S H S⁻¹."""
    return HALF @ np.asarray(H) @ np.linalg.inv(HALF)


def warp_planes(
    frame: NDArray[np.uint8], H: NDArray, full_range: bool = False, border: str = "black"
) -> NDArray[np.uint8]:
    """cv2.warpPerspective of every plane by H (chroma by S H S⁻¹); outside, black (in
    the frame's range) or the ``border`` named (:mod:`stabilize.warp.border`)."""
    mode = opencv_border(border)
    Hc = chroma_homography(H)
    out = np.empty_like(frame)
    # Each plane is warped straight into its place in the output: no joining copy.
    for plane, dst, M, fill in zip(
        split(frame), split(out), (H, Hc, Hc), black(frame, full_range), strict=True
    ):
        size = (plane.shape[1], plane.shape[0])
        cv2.warpPerspective(
            plane, M, size, dst=dst, flags=cv2.INTER_LINEAR, borderMode=mode, borderValue=fill
        )
    return out


def remap_planes(
    frame: NDArray, source: SourceMap, full_range: bool = False, border: str = "black"
) -> NDArray:
    """Warp every plane by a map ``source`` (full-size output pixels → input pixels);
    chroma sees the same map through the half-size coordinates; black outside, or the
    ``border`` named."""
    y, u, v = split(frame)
    coarse = coarse_map(source, y.shape)
    dense = dense_map(coarse, y.shape)
    half = dense_map(half_knots(coarse), u.shape, MAP_STEP // 2)
    fill = black(frame, full_range)
    return join(
        *(
            remap_with(plane, where, value, border)
            for plane, where, value in zip((y, u, v), (dense, half, half), fill, strict=True)
        )
    )


def resize_planes(frame: NDArray[np.uint8], size: tuple[int, int]) -> NDArray[np.uint8]:
    """An I420 frame at (H, W) (both even): every plane resized alike."""
    h, w = size
    y, u, v = split(frame)
    half = (h // 2, w // 2)
    return join(resize_image(y, size), resize_image(u, half), resize_image(v, half))
