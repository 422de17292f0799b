"""Choosing each frame's zoom from the zoom it needs (the crop modes).

* ``auto``: one zoom for the clip, just enough to hide every border (an edited clip's
  shots are planned each on its own, :func:`stabilize.motion.cuts.shots`: one for each);
* ``dynamic``: a smoothly varying zoom, never below any frame's need;
* ``none``: no zoom (borders may show).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from stabilize.path.smoothing import gaussian_band


def auto(need: NDArray, times: NDArray, smooth: float) -> NDArray:
    """The largest need, for every frame."""
    return np.full_like(need, need.max())


def dynamic(need: NDArray, times: NDArray, smooth: float) -> NDArray:
    """The upper envelope of a Gaussian bump 1 + (need_j - 1) g(t - t_j) around every
    frame: never below any frame's need, and it eases in and out of each one. Each bump
    is cut at 4σ (where it is down to 3e-4 of its height), σ = max(smooth, 0.1 s)."""
    bumps = gaussian_band(times, max(smooth, 0.1))
    heights = 1.0 + (need[bumps.indices] - 1.0) * bumps.data
    return np.maximum.reduceat(heights, bumps.indptr[:-1])


def none(need: NDArray, times: NDArray, smooth: float) -> NDArray:
    """No zoom at all."""
    return np.ones_like(need)


# The registry: a crop mode's name → zoom(need, times, smooth).
CROP_MODES: dict[str, Callable[[NDArray, NDArray, float], NDArray]] = {
    "auto": auto,
    "dynamic": dynamic,
    "none": none,
}


def choose_zoom(
    need: NDArray, times: NDArray, crop: str, max_zoom: float, smooth: float
) -> NDArray:
    """Each frame's zoom under crop mode ``crop``, from the zoom each needs (capped at
    ``max_zoom``)."""
    if crop not in CROP_MODES:
        raise ValueError(f"crop must be one of {tuple(CROP_MODES)}, got {crop!r}")
    return CROP_MODES[crop](np.minimum(need, max_zoom), times, smooth)
