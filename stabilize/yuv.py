"""Frames as I420 (planar YUV 4:2:0), the layout H.264 stores; 8 bits (uint8) or 10
(uint16, ``yuv420p10le``), so a 10-bit source stays 10 bits.

Pass 2 decodes, warps and encodes in I420 rather than RGB: FFmpeg then converts no colours
on either side, half as many bytes cross the pipes, and a warp touches 1.5 bytes per
pixel instead of 3. A frame is one (3H/2, W) uint8 array: the luma plane (H, W), then the
two chroma planes (H/2, W/2) one after the other. Both sides must be even.

A chroma plane is the luma plane at half size, with pixel centres at integers in both
(CONVENTIONS.md), so full-size x is 2x' + ½ at half size x', and a full-size homography
H acts on chroma as S H S⁻¹ with S: x' = (x + ½)/2 - ½.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.warping import remap_from, resize_image

BLACK = (16, 128, 128)  # limited-range black: Y, U, V (8 bits; ×4 at 10 bits)
HALF = np.array([[0.5, 0.0, -0.25], [0.0, 0.5, -0.25], [0.0, 0.0, 1.0]])  # S above


def black(frame: NDArray) -> tuple[int, int, int]:
    """Black for a frame's sample depth (uint16 frames carry 10 bits)."""
    scale = 4 if frame.dtype == np.uint16 else 1
    return tuple(v * scale for v in BLACK)


def pipe_format(source_pix_fmt: str) -> str:
    """The I420 pipe format that keeps a source's depth: 10 bits stay 10 bits."""
    return "yuv420p10le" if "10" in source_pix_fmt else "yuv420p"


def pipe_layout(pix_fmt: str, size: tuple[int, int]) -> tuple[tuple[int, ...], type]:
    """(shape, dtype) of one raw frame of (H, W) pixels in FFmpeg's ``pix_fmt``: I420
    (3H/2, W), 8 or 10 bits (``yuv420p10le``: uint16), else RGB (H, W, 3) uint8."""
    h, w = size
    if pix_fmt.startswith("yuv420p"):
        return (h * 3 // 2, w), np.uint16 if pix_fmt.endswith("10le") else np.uint8
    return (h, w, 3), np.uint8


def supports(size: tuple[int, int]) -> bool:
    """Whether an (H, W) frame can travel as I420 (both sides even)."""
    return size[0] % 2 == 0 and size[1] % 2 == 0


def split(frame: NDArray[np.uint8]) -> tuple[NDArray, NDArray, NDArray]:
    """(Y, U, V) views of an I420 frame (3H/2, W)."""
    h = frame.shape[0] * 2 // 3
    w = frame.shape[1]
    chroma = frame[h:].reshape(2, h // 2, w // 2)
    return frame[:h], chroma[0], chroma[1]


def join(y: NDArray, u: NDArray, v: NDArray) -> NDArray[np.uint8]:
    h, w = y.shape
    return np.concatenate([y, np.stack([u, v]).reshape(h // 2, w)])


def chroma_homography(H: NDArray) -> NDArray[np.float64]:
    """The full-size homography H acting on the half-size chroma planes: S H S⁻¹."""
    return HALF @ np.asarray(H) @ np.linalg.inv(HALF)


def warp(frame: NDArray[np.uint8], H: NDArray) -> NDArray[np.uint8]:
    """cv2.warpPerspective of every plane by H (chroma by S H S⁻¹); black outside."""
    Hc = chroma_homography(H)
    out = np.empty_like(frame)
    # Each plane is warped straight into its place in the output: no joining copy.
    for plane, dst, M, fill in zip(
        split(frame), split(out), (H, Hc, Hc), black(frame), strict=True
    ):
        size = (plane.shape[1], plane.shape[0])
        cv2.warpPerspective(plane, M, size, dst=dst, flags=cv2.INTER_LINEAR, borderValue=fill)
    return out


def remap(frame: NDArray, source: Callable[[NDArray], NDArray]) -> NDArray:
    """Warp every plane by a map ``source`` (full-size output pixels → input pixels);
    chroma sees the same map through the half-size coordinates."""
    y, u, v = split(frame)

    def chroma_source(pts: NDArray) -> NDArray:
        return (source(2.0 * pts + 0.5) + 0.5) / 2.0 - 0.5

    fill = black(frame)
    return join(
        remap_from(y, source, fill[0]),
        remap_from(u, chroma_source, fill[1]),
        remap_from(v, chroma_source, fill[2]),
    )


def resize(frame: NDArray[np.uint8], size: tuple[int, int]) -> NDArray[np.uint8]:
    """An I420 frame at (H, W) (both even): every plane resized alike."""
    h, w = size
    y, u, v = split(frame)
    half = (h // 2, w // 2)
    return join(resize_image(y, size), resize_image(u, half), resize_image(v, half))


def hstack(a: NDArray[np.uint8], b: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Two I420 frames side by side."""
    return join(*(np.hstack([p, q]) for p, q in zip(split(a), split(b), strict=True)))


def from_rgb(rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """RGB (H, W, 3) → I420 (limited range, BT.601), for tests and synthetic frames."""
    return cv2.cvtColor(rgb, cv2.COLOR_RGB2YUV_I420)


def to_rgb(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    return cv2.cvtColor(frame, cv2.COLOR_YUV2RGB_I420)
