"""Frames as I420 (planar YUV 4:2:0), the layout H.264 stores; 8 bits (uint8) or 10
(uint16, ``yuv420p10le``), so a 10-bit source stays 10 bits.

Pass 2 decodes, warps and encodes in I420 rather than RGB: FFmpeg then converts no colours
on either side, half as many bytes cross the pipes, and a warp touches 1.5 bytes per
pixel instead of 3. A frame is one (3H/2, W) uint8 array: the luma plane (H, W), then the
two chroma planes (H/2, W/2) one after the other. Both sides must be even.

A source whose colour is finer than 4:2:0 (a camera's or ProRes's 4:2:2, 4:4:4, RGB
pictures), bound for an encoder that keeps colour that fine, travels as RGB instead
(:func:`rgb_pipe`), as does a frame with an odd side: 4:2:0 would halve its colour on
the way.

This module knows the layout only; warping the planes is :mod:`stabilize.warp.planes`.
"""

from __future__ import annotations

import re

import cv2
import numpy as np
from numpy.typing import NDArray

BLACK = (16, 128, 128)  # limited-range black: Y, U, V (8 bits; ×4 at 10 bits)
FULL_RANGE_BLACK = (0, 128, 128)


def black(frame: NDArray, full_range: bool = False) -> tuple[int, int, int]:
    """Black for a frame's sample depth (uint16 frames carry 10 bits) and range."""
    scale = 4 if frame.dtype == np.uint16 else 1
    return tuple(v * scale for v in (FULL_RANGE_BLACK if full_range else BLACK))


def pipe_format(source_pix_fmt: str) -> str:
    """The I420 pipe format that keeps a source's depth, as far as 4:2:0 video holds it:
    a source of 10 bits or more (``yuv420p10le``, ``p010le``, a camera's or a grade's
    ``yuv422p12le``, ``rgb48le``) travels at 10 bits, any other at 8.

    >>> [pipe_format(f) for f in ("yuv420p", "yuvj420p", "p010le", "yuv422p12le", "rgb48le")]
    ['yuv420p', 'yuv420p', 'yuv420p10le', 'yuv420p10le', 'yuv420p10le']
    """
    depth = re.search(r"(\d+)(?:le|be)$", source_pix_fmt)
    return "yuv420p10le" if depth and int(depth.group(1)) >= 10 else "yuv420p"


def is_deep(pix_fmt: str) -> bool:
    """Whether FFmpeg's ``pix_fmt`` holds 10 bits or more a sample (:func:`pipe_format`).

    >>> [is_deep(f) for f in ("yuv420p", "rgb24", "yuv422p10le", "rgb48le", "p010le")]
    [False, False, True, True, True]
    """
    return pipe_format(pix_fmt) != "yuv420p"


def rgb_pipe(source_pix_fmt: str) -> str:
    """The RGB pipe format that keeps a source's depth: 16 bits a channel for a source of
    10 bits or more, else 8.

    >>> [rgb_pipe(f) for f in ("yuv422p", "rgb24", "yuv422p10le", "gbrp16le")]
    ['rgb24', 'rgb24', 'rgb48le', 'rgb48le']
    """
    return "rgb48le" if is_deep(source_pix_fmt) else "rgb24"


def has_alpha(pix_fmt: str) -> bool:
    """Whether FFmpeg's pixel format carries an alpha (transparency) plane, which the
    I420 pipe does not: ProRes 4444's ``yuva444p12le``, a PNG's ``rgba``.

    >>> [has_alpha(f) for f in ("yuva444p12le", "rgba", "gbrap", "yuv420p", "pal8")]
    [True, True, True, False, False]
    """
    return bool(re.match(r"(yuva|rgba|argb|bgra|abgr|gbrap|ya\d)", pix_fmt))


# FFmpeg's packed and semi-planar YUV formats, by their chroma subsampling (the planar
# ones, yuv4XXp, name it themselves)
_PACKED_CHROMA = {
    "4:2:0": ("nv12", "nv21", "p010", "p012", "p016"),
    "4:2:2": ("nv16", "nv20", "p210", "p212", "p216", "y210", "y212", "yuyv422", "uyvy422",
              "yvyu422", "v210"),
    "4:4:4": ("nv24", "nv42", "p410", "p412", "p416", "ayuv", "vuya", "vuyx", "xv30", "xv36",
              "v30x", "y410", "y412"),
}  # fmt: skip


def chroma(pix_fmt: str) -> str | None:
    """The chroma subsampling of FFmpeg's ``pix_fmt`` as J:a:b (RGB: ``4:4:4``), ``""``
    for grey (no colour), None where unknown.

    >>> [chroma(f) for f in ("yuv420p", "yuvj422p", "yuv422p10le", "gbrp", "gray", "p010le")]
    ['4:2:0', '4:2:2', '4:2:2', '4:4:4', '', '4:2:0']
    """
    planar = re.match(r"yuvj?a?(4)(\d)(\d)p", pix_fmt)
    if planar:
        return ":".join(planar.groups())
    if pix_fmt.startswith(("gray", "ya", "mono")):
        return ""
    if re.match(r"(0|x2)?(rgb|bgr|gbr|argb|abgr)|pal8", pix_fmt):
        return "4:4:4"
    return next((j for j, names in _PACKED_CHROMA.items() if pix_fmt.startswith(names)), None)


# The share of the luma's samples each chroma plane keeps, by subsampling
CHROMA_SHARE = {"4:4:4": 1.0, "4:2:2": 0.5, "4:4:0": 0.5, "4:2:0": 0.25, "4:1:1": 0.25}


def finer(pix_fmt: str, than: str) -> bool:
    """Whether FFmpeg's ``pix_fmt`` keeps colour finer than ``than`` does (grey, or a
    format of unknown subsampling, keeps none).

    >>> finer("yuv422p10le", "yuv420p"), finer("rgb24", "yuv422p"), finer("gray", "yuv420p")
    (True, True, False)
    """
    return CHROMA_SHARE.get(chroma(pix_fmt) or "", 0.0) > CHROMA_SHARE.get(chroma(than) or "", 0.0)


def pipe_layout(pix_fmt: str, size: tuple[int, int]) -> tuple[tuple[int, ...], type]:
    """(shape, dtype) of one raw frame of (H, W) pixels in FFmpeg's ``pix_fmt``: I420
    (3H/2, W), 8 or 10 bits (``yuv420p10le``: uint16), else RGB (H, W, 3), 8 or 16 bits
    (``rgb48le``: uint16)."""
    h, w = size
    deep = np.uint16 if is_deep(pix_fmt) else np.uint8
    if pix_fmt.startswith("yuv420p"):
        return (h * 3 // 2, w), deep
    return (h, w, 3), deep


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
    """One I420 frame (3H/2, W) from its planes: the inverse of :func:`split`."""
    h, w = y.shape
    return np.concatenate([y, np.stack([u, v]).reshape(h // 2, w)])


def hstack(a: NDArray[np.uint8], b: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Two I420 frames side by side."""
    return join(*(np.hstack([p, q]) for p, q in zip(split(a), split(b), strict=True)))


def to_rgb(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """I420 (limited range, BT.601) → RGB (H, W, 3)."""
    return cv2.cvtColor(frame, cv2.COLOR_YUV2RGB_I420)
