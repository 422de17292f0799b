"""The image motion the rotation leaves: each pair's 2-D similarity of the background.

A camera that walks past near surfaces also translates, and the parallax it makes is no
rotation: after frame t's static points are turned by R_t, they still land off their
place in frame t+1. A wide or fisheye lens, or a camera's own stabilisation, leaves
motion that no pinhole rotation explains either. Pass 1 measures that remainder as a
similarity in normalised image coordinates (x/f, y/f) about the principal point,

    r(p) = p_{t+1} - π(R_t p_t) ≈ (dx + a·x - b·y,  dy + b·x + a·y),

on every vector within the gate (:func:`gate_px`) of where the rotation puts it, by iteratively
reweighted least squares with Cauchy weights, starting from no motion: the background
the rotation vote found. A subject or a crowd moves further than the gate and is left
out; where it keeps under ``MIN_SHARE`` of a pair's vectors, the background is too
small a part of the frame to tell its roll and zoom, and only its translation counts.
(The Hough inliers alone are the wrong set: the rotation was refined on them, so
their remainder is near zero by construction; on the real clips it did not correlate
with what is left in the output, -0.2 to 0.35, while the whole background's did, 0.75
to 0.8 across, on phone-cc9 and hero7.) The parameters (dx, dy, a, b) are independent
of the frame's size; a pair with too few vectors gets none (zeros).
:mod:`stabilize.path.residual` smooths their chain like the rotation.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.video import frame_interval

MIN_VECTORS = 24  # fewer valid vectors leave the fit to noise: no residual motion
CAUCHY_PX = 0.5  # px at the flow's size: the scale of the Cauchy weights
# px at the flow's size: vectors further than this from where the rotation puts them
# are not background (a subject, a crowd: a bird filling the frame dragged the fit
# 48 px a frame without it). Near static surfaces belong in: on hero7 (a walk past
# plants that loom about 3 px a frame here) 3 px kept a median 80% of a pair's vectors
# and the output read 1.260 px against vid.stab's 1.164; 4.5 px keeps 94%, and 4, 4.5, 5
# and 6 px read 1.176, 1.149, 1.161 and 1.184 (lossless, mirrored means). The other real
# clips stay within their spread (karma 0.520 → 0.487), the rendered distant scenes the
# same to 0.3%
GATE_PX = 4.5
# ... per this long between a pair's frames (s): a pair that spans longer widens the gate
# in proportion, since a near surface's parallax and a subject's motion both grow with
# the time between the frames, and the gate tells them apart. At half their rate
# (every other frame; lossless, the means of 20 readings), at 4.5 px and at 9: hero7
# 1.648 → 1.525 px, max-heromode 1.155 → 1.058, a rendered 100° walk 0.663 → 0.636;
# phone-cc9's frames, their 31° crop, karma and a 70° walk within their readings'
# noise (docs/remainder.md). At a faster rate the gate stays: from 45 fps pass 1 also
# measures strides of about a thirtieth of a second (stabilize.motion.strides), whose
# own times give them their gate. NTSC's 29.97 fps counts as 30
GATE_INTERVAL_S = 1001 / 30000
IRLS_STEPS = 5
# The share of a pair's valid vectors the gate must keep for its roll and zoom (a, b) to
# count: below it, a subject close to the lens likely won the vote, and its approach
# would read as the camera's zoom. The real clips' lowest pairs kept 0.45–0.57 (hero7,
# phone-cc9); cockatoo, a bird filling the frame, kept under 0.4 in 35% of its pairs,
# where `similarity` shook 18.5 px without this and 15.1 with it (0.6 cost hero7 0.07 px
# for one pair that zoomed; taking the neighbours' zoom instead cost cockatoo 1.4 px)
MIN_SHARE = 0.4


def gate_px(times: NDArray) -> float:
    """The gate (px at the flow's size) for a clip whose frames come at ``times`` (s):
    ``GATE_PX`` for pairs ``GATE_INTERVAL_S`` apart or less, widened in proportion to
    the median time between its frames where that is longer."""
    widened = round(frame_interval(np.asarray(times)) / GATE_INTERVAL_S, 3)  # (to 0.1%)
    return GATE_PX * max(1.0, widened)


def design(xn: NDArray, yn: NDArray) -> tuple[NDArray, NDArray]:
    """The similarity's design rows (M, 4) for the x and the y residuals at normalised
    points (xn, yn): r_x = A_x·(dx, dy, a, b), r_y = A_y·(dx, dy, a, b)."""
    one, zero = np.ones_like(xn), np.zeros_like(xn)
    return np.stack([one, zero, xn, -yn], 1), np.stack([zero, one, yn, xn], 1)


def fit_similarity(
    xn: NDArray, yn: NDArray, rx: NDArray, ry: NDArray, weights: NDArray, scale: float
) -> NDArray[np.float64]:
    """(dx, dy, a, b) (n, 4) of residuals rx, ry (n, M) at points (xn, yn) (M,), by
    IRLS with Cauchy weights w = 1 / (1 + |e|²/scale²) (``scale`` in the residuals'
    units; inf: least squares), starting from no motion; zeros where fewer than
    ``MIN_VECTORS`` points have weight."""
    ax, ay = design(xn, yn)
    gram = ax[:, :, None] * ax[:, None, :] + ay[:, :, None] * ay[:, None, :]  # (M, 4, 4)
    base = np.asarray(weights, np.float64)
    params = np.zeros((len(rx), 4))
    enough = (base > 0).sum(axis=1) >= MIN_VECTORS
    if not enough.any():
        return params
    for _ in range(IRLS_STEPS if np.isfinite(scale) else 1):
        ex = rx - params @ ax.T
        ey = ry - params @ ay.T
        w = base / (1.0 + (ex * ex + ey * ey) / scale**2)
        normal = np.einsum("nm,mij->nij", w, gram) + 1e-9 * np.eye(4)
        rhs = (w * rx) @ ax + (w * ry) @ ay
        params = np.linalg.solve(normal, rhs[..., None])[..., 0]
    return np.where(enough[:, None], params, 0.0)


def landing(x: NDArray, y: NDArray, R: NDArray, focal: float) -> tuple[NDArray, NDArray]:
    """Where rotations R (n, 3, 3) put points (x, y) (M,) about the principal point, in
    pixels at ``focal``: π(R (x, y, f)) in normalised coordinates, (n, M) each."""
    rays = np.stack([x, y, np.full_like(x, focal)], 1)
    return normalised(rays @ np.swapaxes(np.asarray(R, np.float64), -1, -2))  # (n, M, 3)


def normalised(rays: NDArray) -> tuple[NDArray, NDArray]:
    """π(p): the normalised image coordinates (x/z, y/z) of rays (..., 3)."""
    z = np.maximum(rays[..., 2], 1e-9)
    return rays[..., 0] / z, rays[..., 1] / z


def residual_motion(
    x: NDArray,
    y: NDArray,
    u: NDArray,
    v: NDArray,
    valid: NDArray,
    R: NDArray,
    focal: float,
    gate: float = GATE_PX,
) -> NDArray[np.float64]:
    """Each pair's similarity (n, 4) left after its rotation: sample points (x, y) (M,)
    about the principal point, their flow u, v (n, M) where ``valid`` (n, M), rotations
    R (n, 3, 3), in pixels at focal length ``focal``; ``gate`` (px, :func:`gate_px`)."""
    lx, ly = landing(x, y, R, focal)
    rx, ry = (x + u) / focal - lx, (y + v) / focal - ly
    return background_similarity(x, y, rx, ry, valid, focal, gate)


def background_similarity(
    x: NDArray,
    y: NDArray,
    rx: NDArray,
    ry: NDArray,
    valid: NDArray,
    focal: float,
    gate: float = GATE_PX,
) -> NDArray[np.float64]:
    """The similarity (n, 4) of the remainders rx, ry (n, M, normalised) at points (x, y)
    (M,, px about the principal point) that lie within ``gate`` px of no motion."""
    near = valid & (np.hypot(rx, ry) < gate / focal)
    params = fit_similarity(x / focal, y / focal, rx, ry, near, CAUCHY_PX / focal)
    kept = near.sum(axis=1) >= MIN_SHARE * np.maximum(valid.sum(axis=1), 1)
    params[~kept, 2:] = 0.0  # too little background to tell its roll and zoom
    return params


def reexpress(
    residual: NDArray, R_from: NDArray, R_to: NDArray, focal: float, size: tuple[int, int]
) -> NDArray[np.float64]:
    """The residual similarities (n, 4) measured after rotations ``R_from`` re-expressed
    after rotations ``R_to`` (a gyro's, for the same pairs): the similarity that best
    fits the flow of R_from R_toᵀ over the frame is added. (The first-order part of
    that flow is a translation and a roll; a gyro's rotation differs from the visual
    one by a fraction of a degree.)"""
    h, w = size
    gx, gy = np.meshgrid(np.linspace(-w / 2, w / 2, 9), np.linspace(-h / 2, h / 2, 7))
    x, y = gx.ravel(), gy.ravel()
    fx, fy = landing(x, y, R_from, focal)
    tx, ty = landing(x, y, R_to, focal)
    ones = np.ones((len(residual), len(x)))
    delta = fit_similarity(x / focal, y / focal, fx - tx, fy - ty, ones, np.inf)
    return np.asarray(residual, np.float64) + delta
