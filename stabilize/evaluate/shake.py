"""Residual shake: what a viewer sees as shake, in pixels.

Consecutive frames are registered by a similarity (ORB features spread over the frame,
each match refined to a fraction of a pixel by :func:`subpixel`, RANSAC), the 2-D motion
a viewer's eye follows. Each frame-to-frame similarity becomes a motion vector in pixels
at the clip's width w,

    v_t = (dx, dy, dθ · w/2, d(ln s) · w/2),

the translation and what the rotation and the zoom move the frame's side by. A Gaussian
low-pass (σ = ``CUTOFF_S`` = 0.5 s) keeps what is intended (a pan, a walk's drift); the
residual shake is the RMS length of what is left,

    shake_px = √ mean_t |v_t - (G_σ * v)_t|²,

and ``shake_deg`` the same for the in-plane rotation alone, in degrees; the RMS of each
component alone (:func:`shake_components`) are its parts. Lower is steadier; a tripod
shot scores about 0.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import gaussian_filter1d

CUTOFF_S = 0.5  # σ of the low-pass that separates intended motion from shake
MIN_MATCHES = 12
# How far a fit's inliers must spread, as a share of the frame's width, for the fit to be
# determined: a similarity needs it overall (RMS distance from their centroid), a
# homography across their narrowest direction too. On the feathers of a crop of
# cockatoo.mp4, 13 inliers within 22×6 px of a 640 px frame fitted a similarity of scale
# 1e-17 (the clip read 724 px of shake), and 25 in a strip 46 px across a homography whose
# "distortion" read 0.11; features spread evenly over a 16:9 frame spread 0.16 of the
# width across its height
MIN_SPREAD = 0.03
# The sub-pixel refinement (:func:`subpixel`): Lucas-Kanade windows of 15 px at the
# registration's size (640 px on the long side), one pyramid level above it (it starts at
# the match, within a pixel or two), and how far tracking back may land from the start
BACK_PX = 0.25
_LK = {
    "winSize": (15, 15),
    "maxLevel": 1,
    "criteria": (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01),
}


def matched_points(
    a: tuple[NDArray, NDArray | None], b: tuple[NDArray, NDArray | None], matcher
) -> tuple[NDArray, NDArray] | None:
    """The features of frame a and of frame b that match (points in the frames' pixels,
    descriptors; ratio test), or None where too few do."""
    (pa, da), (pb, db) = a, b
    if da is None or db is None or len(pa) < MIN_MATCHES or len(pb) < MIN_MATCHES:
        return None
    pairs = matcher.knnMatch(da, db, k=2)
    good = [m[0] for m in pairs if len(m) == 2 and m[0].distance < 0.8 * m[1].distance]
    if len(good) < MIN_MATCHES:
        return None
    return pa[[m.queryIdx for m in good]], pb[[m.trainIdx for m in good]]


def subpixel(
    grey_a: NDArray[np.uint8],
    grey_b: NDArray[np.uint8],
    src: NDArray,
    dst: NDArray,
    scale: float = 1.0,
) -> tuple[NDArray, NDArray]:
    """Matched points (``src`` in frame a, ``dst`` in frame b, px of the frames) with
    ``dst`` moved to where frame a's patch around ``src`` lies in frame b, to a fraction
    of a pixel: pyramidal Lucas-Kanade on the grey images (``scale`` frame px to one of
    theirs), started at ``dst``, kept where tracking back lands within ``BACK_PX`` of
    ``src``. Where fewer than ``MIN_MATCHES`` are kept, the matches as they are.

    ORB places its keypoints on each pyramid level's pixel grid, so a match is off by up
    to half a pixel there, and the error follows the content's sub-pixel phase rather
    than averaging out: a frame of phone-cc9 panned 0.93 px a frame, which has no
    shake, read 0.335 px of residual shake, and shaken by 0.138 px (RMS, high-passed)
    without a pan, 0.019; refined so, 0.006 and 0.138 (the procedural texture of
    ``tests/stabilize/evaluate/test_shake.py``: 0.264 and 0.034, refined 0.018 and 0.143).
    """
    p0 = (np.asarray(src, np.float32) / scale).reshape(-1, 1, 2)
    guess = (np.asarray(dst, np.float32) / scale).reshape(-1, 1, 2)
    p1, found, _ = cv2.calcOpticalFlowPyrLK(
        grey_a, grey_b, p0, guess.copy(), flags=cv2.OPTFLOW_USE_INITIAL_FLOW, **_LK
    )
    back, returned, _ = cv2.calcOpticalFlowPyrLK(
        grey_b, grey_a, p1, p0.copy(), flags=cv2.OPTFLOW_USE_INITIAL_FLOW, **_LK
    )
    err = np.linalg.norm((back - p0).reshape(-1, 2), axis=1)
    kept = (found.ravel() == 1) & (returned.ravel() == 1) & (err < BACK_PX)
    if kept.sum() < MIN_MATCHES:
        return src, dst
    return np.asarray(src)[kept], p1.reshape(-1, 2)[kept] * scale


def principal_spread(points: NDArray) -> NDArray[np.float64]:
    """The standard deviations of points (M, 2) along their principal axes, the smaller
    first (zeros for fewer than 3 points)."""
    p = np.asarray(points, np.float64)
    if len(p) < 3:
        return np.zeros(2)
    return np.sqrt(np.maximum(np.linalg.eigvalsh(np.cov(p.T)), 0.0))


def similarity_motion(src: NDArray, dst: NDArray, width: int) -> NDArray[np.float64] | None:
    """(dx, dy, dθ, d ln s) of the similarity taking matched points ``src`` to ``dst``
    (RANSAC) in a frame ``width`` px wide, or None where too few agree or they bunch
    together in either frame (their RMS distance from their centroid under ``MIN_SPREAD``
    of the width: features of one frame matched to one point of the other fit a
    similarity that sends everything there)."""
    M, inliers = cv2.estimateAffinePartial2D(src, dst, method=cv2.RANSAC, ransacReprojThreshold=1.5)
    if M is None or inliers.sum() < MIN_MATCHES:
        return None
    kept = inliers.ravel() > 0
    overall = min(float(np.linalg.norm(principal_spread(pts[kept]))) for pts in (src, dst))
    scale = float(np.hypot(M[0, 0], M[1, 0]))
    if overall < MIN_SPREAD * width or not scale > 0:  # (scale 0: all sent to one place)
        return None
    return np.array([M[0, 2], M[1, 2], np.arctan2(M[1, 0], M[0, 0]), np.log(scale)])


def high_passed(
    motions: NDArray, width: int, fps: float, center: tuple[float, float] | None = None
) -> NDArray[np.float64]:
    """v_t - (G_σ * v)_t (N, 4): what a viewer sees as shake in each frame-to-frame
    similarity motion (N, 4) at ``fps``, as (dx, dy, roll, zoom) in px at the clip's
    ``width``. The translation is taken at the frame's ``center`` (the similarity's own
    is that of the pixel origin, a corner, which a small rotation moves far more than the
    middle)."""
    motions = np.asarray(motions, dtype=np.float64).reshape(-1, 4)
    dx, dy, dtheta, dlog = motions.T
    if center is not None:  # the translation of the frame's centre, not of its corner
        cx, cy = center
        c, s, k = np.cos(dtheta), np.sin(dtheta), np.exp(dlog)
        dx = dx + k * (c * cx - s * cy) - cx
        dy = dy + k * (s * cx + c * cy) - cy
    v = np.stack([dx, dy, dtheta * width / 2, dlog * width / 2], 1)
    if len(v) == 0:
        return v
    return v - gaussian_filter1d(v, sigma=max(CUTOFF_S * fps, 1.0), axis=0, mode="nearest")


def shake_components(
    motions: NDArray, width: int, fps: float, center: tuple[float, float] | None = None
) -> NDArray[np.float64]:
    """The RMS of each :func:`high_passed` component, (dx, dy, roll, zoom) in px
    (:func:`parts_of`)."""
    return parts_of(high_passed(motions, width, fps, center))


def parts_of(high: NDArray) -> NDArray[np.float64]:
    """The RMS of each component of a :func:`high_passed` series (N, 4); NaN for fewer
    than 3 motions. Which component dominates tells what is left: on a walk past near
    surfaces the zoom is the similarity fit's choice between depth layers, and differs
    from one output of the same clip to the next (GoPro hero7: 1.02–1.24 px)."""
    if len(high) < 3:
        return np.full(4, np.nan)
    return np.sqrt(np.mean(np.asarray(high) ** 2, axis=0))


def residual_shake(components: NDArray, width: int) -> tuple[float, float]:
    """(shake_px, shake_deg) of a clip ``width`` px wide from its
    :func:`shake_components`: their length, and the roll's in degrees."""
    parts = np.asarray(components, np.float64)
    return float(np.sqrt(np.sum(parts**2))), float(np.degrees(parts[2] * 2 / width))
