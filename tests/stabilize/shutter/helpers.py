"""Band rotations of a known continuous camera path, as pass 1 would measure them."""

from __future__ import annotations

import numpy as np

from rotation import so3
from stabilize.motion.track import VisualTrack
from stabilize.synth.trajectory import Handheld, orientation

FPS = 30.0


def between(motion: Handheld, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """R(a → b) = O(b) O(a)ᵀ of the path."""
    return orientation(motion, b) @ np.swapaxes(orientation(motion, a), -1, -2)


def banded_track(
    readout: float | np.ndarray,
    shake_deg: float = 3.0,
    seconds: float = 3.0,
    bands: int = 6,
    noise_deg: float = 0.05,
    seed: int = 0,
) -> tuple[VisualTrack, Handheld]:
    """A track whose band b of pair k turned from t_k + r·y_b to t_{k+1} + r·y_b, with
    ``noise_deg`` of measurement noise per axis; the whole frame's seen at y = ½.
    ``readout``: r, or one per pair."""
    motion = Handheld(seconds, seed, shake_deg, pan_deg=10.0, walk=0.0)
    rng = np.random.default_rng(seed)
    times = np.arange(int(seconds * FPS) + 1) / FPS
    heights = (np.arange(bands) + 0.5) / bands
    n = len(times) - 1

    def seen(y: float) -> np.ndarray:
        R = between(motion, times[:-1] + readout * y, times[1:] + readout * y)
        return so3.exp_so3(rng.normal(0, np.radians(noise_deg), (n, 3))) @ R

    band_R = np.stack([seen(y) for y in heights])
    track = VisualTrack(
        times,
        seen(0.5),
        np.full(n, 0.4),
        np.full(n, 0.5),
        band_R,
        np.repeat(heights[:, None], n, 1),
        np.full((bands, n), 0.3),
    )
    return track, motion
