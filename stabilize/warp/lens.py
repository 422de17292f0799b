"""Lens profiles (Gyroflow's JSON) and the OpenCV fisheye model.

A ray (X, Y, Z) at angle θ = atan2(√(X²+Y²), Z) from the axis is imaged at

    θ_d = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸),   (u, v) = (fx θ_d cos φ + cx, fy θ_d sin φ + cy)

with φ the ray's azimuth. Unlike a pinhole this stays defined beyond 90°. Unprojecting
inverts θ_d(θ) by Newton's method. A profile is calibrated at ``calib_dimension``; the
matrix is scaled to the video's size (CONVENTIONS.md: c + ½ scales with the image).

Stabilising a fisheye clip then means: unproject each output pixel with the output
camera (the same lens, focal length times the zoom), turn the ray by the correction,
and project it with the input camera, all in one ``cv2.remap``
(:func:`stabilize.warp.sources.lens_source`, then :func:`stabilize.warp.remap.remap_from`),
so the edges do not wobble as they do when a fisheye frame is warped by a homography.
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rotation.camera import scale_intrinsics

NEWTON_STEPS = 8
MODELS = ("opencv_fisheye",)


class LensError(ValueError):
    """A lens profile that cannot be used; the message names the file and the problem."""


@dataclass(frozen=True)
class Lens:
    K: NDArray[np.float64]  # 3×3 at the video's size
    coeffs: NDArray[np.float64]  # k1..k4
    readout_s: float | None = None  # the profile's frame_readout_time
    source: str = ""


def read_lens_profile(path: str | Path, size: tuple[int, int] | None = None) -> Lens:
    """A Gyroflow lens profile, scaled to a video of (H, W) pixels as its sensor stores
    them (:meth:`stabilize.video.VideoInfo.stored`), the frames it was calibrated on;
    without ``size``, at the size it was calibrated at (a check before a batch's clips)."""
    path = Path(path)
    try:
        profile = json.loads(path.read_text())
    except FileNotFoundError:
        raise LensError(f"{path}: no such lens profile") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise LensError(f"{path}: not a Gyroflow lens profile (JSON): {err}") from None
    model = profile.get("distortion_model") or "opencv_fisheye"
    if model not in MODELS:
        raise LensError(f"{path}: distortion model {model!r} is not supported ({MODELS})")
    try:
        params = profile["fisheye_params"]
        K = np.array(params["camera_matrix"], dtype=np.float64).reshape(3, 3)
        coeffs = np.array(params["distortion_coeffs"], dtype=np.float64)[:4]
        calib = profile["calib_dimension"]
        cw, ch = float(calib["w"]), float(calib["h"])
    except (KeyError, TypeError, ValueError) as err:
        raise LensError(f"{path}: missing or malformed lens field {err}") from None
    if coeffs.size != 4 or not np.isfinite(K).all() or K[0, 0] <= 0 or cw <= 0 or ch <= 0:
        raise LensError(f"{path}: needs a camera matrix, 4 fisheye coefficients and a size")
    h, w = size or (ch, cw)
    if abs((w / h) / (cw / ch) - 1.0) > 0.01:
        raise LensError(
            f"{path}: calibrated at {cw:.0f}x{ch:.0f}, a different aspect ratio from the "
            f"video's {w}x{h} as stored; choose the profile for this recording mode"
        )
    readout = profile.get("frame_readout_time")
    readout_s = float(readout) / 1000.0 if readout else None
    return Lens(scale_intrinsics(K, w / cw, h / ch), coeffs, readout_s, str(path))


def project(lens: Lens, rays: NDArray) -> NDArray[np.float64]:
    """Pixels (M, 2) of rays (M, 3); NaN for rays behind the lens's reach."""
    rays = np.asarray(rays, dtype=np.float64)
    r = np.hypot(rays[:, 0], rays[:, 1])
    theta = np.arctan2(r, rays[:, 2])
    t2 = theta * theta
    k1, k2, k3, k4 = lens.coeffs
    theta_d = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
    scale = np.where(r > 1e-12, theta_d / np.where(r > 1e-12, r, 1.0), 1.0 / rays[:, 2])
    uv = np.stack(
        [
            lens.K[0, 0] * rays[:, 0] * scale + lens.K[0, 2],
            lens.K[1, 1] * rays[:, 1] * scale + lens.K[1, 2],
        ],
        -1,
    )
    uv[theta > max_angle(lens)] = np.nan
    return uv


def unproject(lens: Lens, pts: NDArray) -> NDArray[np.float64]:
    """Unit rays (M, 3) of pixels (M, 2)."""
    pts = np.asarray(pts, dtype=np.float64)
    x = (pts[:, 0] - lens.K[0, 2]) / lens.K[0, 0]
    y = (pts[:, 1] - lens.K[1, 2]) / lens.K[1, 1]
    theta_d = np.hypot(x, y)
    theta = np.minimum(theta_d, max_angle(lens))
    k1, k2, k3, k4 = lens.coeffs
    for _ in range(NEWTON_STEPS):
        t2 = theta * theta
        f = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)))) - theta_d
        df = 1 + t2 * (3 * k1 + t2 * (5 * k2 + t2 * (7 * k3 + t2 * 9 * k4)))
        theta = np.clip(theta - f / df, 0.0, max_angle(lens))
    s = np.where(theta_d > 1e-12, np.sin(theta) / np.where(theta_d > 1e-12, theta_d, 1.0), 1.0)
    return np.stack([x * s, y * s, np.cos(theta)], -1)


def max_angle(lens: Lens) -> float:
    """The largest θ where θ_d(θ) still increases (beyond it the model folds back), ≤ π."""
    return _max_angle(tuple(float(k) for k in lens.coeffs))


@functools.lru_cache(maxsize=32)
def _max_angle(coeffs: tuple[float, float, float, float]) -> float:
    theta = np.linspace(0.0, np.pi, 2001)
    t2 = theta * theta
    k1, k2, k3, k4 = coeffs
    slope = 1 + t2 * (3 * k1 + t2 * (5 * k2 + t2 * (7 * k3 + t2 * 9 * k4)))
    bad = np.flatnonzero(slope <= 0)
    return float(theta[bad[0] - 1]) if bad.size else float(np.pi)


def pinhole_map(
    lens: Lens, size: tuple[int, int], focal: float, center: tuple[float, float]
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """cv2.remap maps that turn a frame of this lens (at ``size``) into a pinhole view with
    ``focal`` and ``center``: what the rotation estimator expects."""
    h, w = size
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    rays = np.stack([(xs - center[0]) / focal, (ys - center[1]) / focal, np.ones_like(xs)], -1)
    src = project(lens, rays.reshape(-1, 3)).reshape(h, w, 2)
    src = np.nan_to_num(src, nan=-1e4).astype(np.float32)
    return src[..., 0], src[..., 1]
