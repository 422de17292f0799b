"""A handheld camera's path: slow intentional pan, hand shake, walking with bob and sway.

Orientation is kept as C(t), the camera-to-world rotation (world axes are the first
frame's camera axes: x right, y down, z forward); O(t) = C(t)ᵀ is the orientation of
CONVENTIONS.md and R_t = O(t_{k+1}) O(t_k)ᵀ. The body angular velocity in camera axes
is ω with Ċ = C [ω]×, so R over a short interval is exp(-[ω Δt]×), as a gyro sees it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rotation import so3

SHAKE_BAND_HZ = (1.0, 9.0)
SHAKE_TONES = 12  # sinusoids per axis in the band-limited shake


@dataclass(frozen=True)
class Handheld:
    """Parameters of the motion, all deterministic given ``seed``.

    shake_deg is the RMS of the shake angle per axis; pan_deg the total yaw of the
    intentional pan over ``seconds``; walk the forward speed in m/s.
    """

    seconds: float
    seed: int = 0
    shake_deg: float = 1.0
    pan_deg: float = 10.0
    walk: float = 1.0
    bob_m: float = 0.02
    sway_m: float = 0.015
    step_hz: float = 1.8


@dataclass(frozen=True)
class _Tones:
    freq: NDArray  # (3, k) Hz
    phase: NDArray  # (3, k)
    amp: NDArray  # (3, k) radians


def _tones(motion: Handheld) -> _Tones:
    rng = np.random.default_rng(motion.seed)
    lo, hi = SHAKE_BAND_HZ
    freq = np.exp(rng.uniform(np.log(lo), np.log(hi), (3, SHAKE_TONES)))
    phase = rng.uniform(0, 2 * np.pi, (3, SHAKE_TONES))
    # Hand tremor carries more amplitude at low frequency: weight ∝ 1/f, then scale so
    # that the RMS angle per axis is shake_deg (roll gets half).
    amp = 1.0 / freq
    amp *= np.sqrt(2.0) / np.sqrt(np.sum(amp**2, axis=1, keepdims=True))
    amp *= np.radians(motion.shake_deg) * np.array([[1.0], [1.0], [0.5]])
    return _Tones(freq, phase, amp)


def camera_rotvec(motion: Handheld, t: NDArray) -> NDArray[np.float64]:
    """Rotation vector (pitch, yaw, roll about x, y, z) of C(t), shape (..., 3)."""
    t = np.asarray(t, dtype=np.float64)
    tones = _tones(motion)
    arg = 2 * np.pi * tones.freq * t[..., None, None] + tones.phase
    shake = np.sum(tones.amp * np.sin(arg), axis=-1)
    # The pan eases in and out (a raised cosine), as a person turning does.
    progress = np.clip(t / max(motion.seconds, 1e-9), 0.0, 1.0)
    pan = np.radians(motion.pan_deg) * 0.5 * (1 - np.cos(np.pi * progress))
    shake[..., 1] += pan
    return shake


def camera_to_world(motion: Handheld, t: NDArray) -> NDArray[np.float64]:
    """C(t), (..., 3, 3)."""
    return so3.exp_so3(camera_rotvec(motion, t))


def orientation(motion: Handheld, t: NDArray) -> NDArray[np.float64]:
    """O(t) = C(t)ᵀ: maps world directions to camera axes (CONVENTIONS.md)."""
    return np.swapaxes(camera_to_world(motion, t), -1, -2)


def position(motion: Handheld, t: NDArray) -> NDArray[np.float64]:
    """Camera centre in world metres, (..., 3): forward walk with bob and sway."""
    t = np.asarray(t, dtype=np.float64)
    x = motion.sway_m * np.sin(np.pi * motion.step_hz * t)
    y = motion.bob_m * np.sin(2 * np.pi * motion.step_hz * t)
    z = motion.walk * t
    return np.stack([x, y, z], axis=-1)


def angular_velocity(motion: Handheld, t: NDArray, dt: float = 1e-4) -> NDArray[np.float64]:
    """ω(t) in camera axes, rad/s: log(C(t)ᵀ C(t + dt)) / dt, centred."""
    t = np.asarray(t, dtype=np.float64)
    a = camera_to_world(motion, t - dt / 2)
    b = camera_to_world(motion, t + dt / 2)
    return so3.log_so3(np.swapaxes(a, -1, -2) @ b) / dt


def relative_rotations(motion: Handheld, times: NDArray) -> NDArray[np.float64]:
    """R_t = O(t_{k+1}) O(t_k)ᵀ for consecutive times, (len - 1, 3, 3)."""
    O = orientation(motion, times)
    return O[1:] @ np.swapaxes(O[:-1], -1, -2)
