"""Sensor noise: how grainy a frame is, and the blur DIS looks through.

A clip shot in low light carries noise that changes from frame to frame, and DIS's
small patches match it along with the picture. Measured against the real gyros, the
visual turns of karma and of phone-cc9's frames, dimmed and grained as such a clip is
(contrast 0.55, brightness −0.22, FFmpeg's ``noise=alls=22:allf=t+u``), erred 0.052°
and 0.093° a frame (mean angular error; clean 0.022° and 0.057°). Blurred by a
Gaussian of 1 px (at the flow's working size) before DIS, they erred 0.034° and 0.072°,
and the clean ones 0.023° and 0.051°. But the blur costs a clean clip its finest
detail: cockatoo's output, whose bird's feathers are that detail, shook 13.77 px
blurred 15.56 (mirrored means, lossless). So the blur follows the noise measured in
each frame: none on a clean one, all of it on a grainy one.

The noise is Immerkær's estimate (1996): the frame filtered by the difference of two
Laplacians, which cancels planes and straight ramps, its mean absolute response times
√(π/2)/6 for Gaussian noise of σ grey levels. Texture answers it too, so it is read in
16 px blocks and the 10th percentile of them taken: the flattest tenth of the frame (a
sky, a wall), where what is left is noise. At the flow's working size the real clips
here read 0.05–0.29 grey levels (single frames up to 0.37), their dimmed and grained
copies 2.2–2.4 (cockatoo's 0.9–1.9: the bird fills its frames). A scene textured
everywhere at the finest scale reads as noise: the rendered clips' 0.66–1.39.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numpy.typing import NDArray

# The difference of two 3×3 Laplacians: zero on any plane and any straight ramp
_MASK = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float32)
_GAUSS = math.sqrt(math.pi / 2) / 6  # mean |response| → σ, for Gaussian noise
BLOCK_PX = 16  # the blocks the response is averaged over
FLATTEST = 10  # percentile of the blocks read: the frame's flattest tenth
# grey levels: no blur up to here. The real clips' frames read at most 0.37, but the
# rendered clips' fine procedural texture, which covers every block, reads 0.66–0.93 at
# 960×540: above them, so that the benches' rendered figures stay as they were (a 10 s
# 1080p render reads 0.95–1.39, and 46 of its 300 frames' pairs are blurred by under
# 0.2 px: its turns' mean error against the truth 0.0222° → 0.0218°)
NOISY = 1.25
GRAINY = 2.0  # grey levels: the whole blur from here (the grained copies read 2.2–2.4)
BLUR_PX = 1.0  # Gaussian σ from GRAINY up, px at the flow's working size


def noise_level(grey: NDArray[np.uint8]) -> float:
    """σ of a grey frame's noise, grey levels (0–255), read on its flattest blocks.

    σ ≈ √(π/2)/6 · P₁₀(mean_B |I * M|), M = [[1, −2, 1], [−2, 4, −2], [1, −2, 1]], over
    blocks B of 16 px (Immerkær 1996, on the flattest tenth of the frame). A frame under
    two blocks across either way is read whole.
    """
    response = np.abs(cv2.filter2D(grey, cv2.CV_32F, _MASK)[1:-1, 1:-1])
    h, w = response.shape
    rows, cols = h // BLOCK_PX, w // BLOCK_PX
    if rows < 2 or cols < 2:
        return float(_GAUSS * response.mean())
    whole = response[: rows * BLOCK_PX, : cols * BLOCK_PX]
    blocks = cv2.resize(whole, (cols, rows), interpolation=cv2.INTER_AREA)
    return float(_GAUSS * np.percentile(blocks, FLATTEST))


def blur_for(noise: float) -> float:
    """The Gaussian σ (px) a pair whose grainier frame reads ``noise`` grey levels is
    blurred by before its flow: 0 up to ``NOISY``, rising linearly to ``BLUR_PX`` at
    ``GRAINY`` and over."""
    share = (noise - NOISY) / (GRAINY - NOISY)
    return BLUR_PX * min(1.0, max(0.0, share))


def through_grain(
    grey0: NDArray[np.uint8], grey1: NDArray[np.uint8], noise0: float, noise1: float
) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
    """The pair as the flow sees it: both frames blurred by :func:`blur_for` of the
    grainier one's noise, or the frames themselves where neither is grainy."""
    sigma = blur_for(max(noise0, noise1))
    if sigma == 0.0:
        return grey0, grey1
    return cv2.GaussianBlur(grey0, (0, 0), sigma), cv2.GaussianBlur(grey1, (0, 0), sigma)
