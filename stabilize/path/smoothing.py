"""Smoothing the camera's orientation path on SO(3) (never on Euler angles).

Orientations O_t (world → camera) are averaged in the tangent space of each frame:

    S_t = exp( Σ_j w_tj log(O_j O_tᵀ) ) O_t,     Σ_j w_tj = 1,

one Gauss-Newton step of the weighted Karcher mean, which is exact enough at the small
angles a hand covers within a smoothing window. The weights are a Gaussian in time
(zero phase: no lag), with σ = ``smooth`` seconds.

``adaptive`` narrows the window where the camera turns fast, so intentional pans are
followed closely while shake is still removed (the idea of Gyroflow's default). ``lock``
holds one orientation, as on a tripod.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from rotation import so3

if TYPE_CHECKING:
    from scipy.sparse import csr_array

ADAPTIVE_REF_DEG_S = 30.0  # angular speed at which the window halves


def gaussian_band(times: NDArray, sigma: float, reach: float = 4.0) -> csr_array:
    """g_ij = exp(-½ ((t_i - t_j) / σ)²) for |t_i - t_j| ≤ reach·σ, else 0: an (N, N)
    sparse matrix over sorted ``times``, whose memory grows with the clip's length, not
    with its square (a dense one would need 2.6 GB for ten minutes at 30 fps).

    >>> gaussian_band(np.arange(5) / 30, 0.01).nnz  # each frame, and its neighbours
    13
    """
    from scipy.sparse import csr_array  # loaded with the planner, not the command line

    times = np.asarray(times, dtype=np.float64)
    n = len(times)
    lo = np.searchsorted(times, times - reach * sigma)
    hi = np.searchsorted(times, times + reach * sigma, side="right")
    counts = hi - lo
    rows = np.repeat(np.arange(n), counts)
    starts = np.repeat(np.cumsum(counts) - counts, counts)  # each row's first entry
    cols = np.repeat(lo, counts) + np.arange(counts.sum()) - starts
    weights = np.exp(-0.5 * ((times[rows] - times[cols]) / sigma) ** 2)
    return csr_array((weights, (rows, cols)), shape=(n, n))


def _gaussian_mean(O: NDArray, times: NDArray, sigma: NDArray) -> NDArray:
    n = len(O)
    out = np.empty_like(O)
    for t in range(n):
        s = max(float(sigma[t]), 1e-6)
        lo = np.searchsorted(times, times[t] - 3 * s)
        hi = np.searchsorted(times, times[t] + 3 * s, side="right")
        w = np.exp(-0.5 * ((times[lo:hi] - times[t]) / s) ** 2)
        w /= w.sum()
        tangent = so3.log_so3(O[lo:hi] @ O[t].T)
        out[t] = so3.exp_so3(w @ tangent) @ O[t]
    return out


def angular_speed(O: NDArray, times: NDArray) -> NDArray:
    """|ω| per frame in rad/s, from consecutive orientations (last repeated)."""
    if len(O) < 2:
        return np.zeros(len(O))
    R = O[1:] @ np.swapaxes(O[:-1], -1, -2)
    speed = so3.angle(R) / np.maximum(np.diff(times), 1e-6)
    return np.append(speed, speed[-1])


def gaussian(O: NDArray, times: NDArray, smooth: float) -> NDArray[np.float64]:
    """A Gaussian window of σ = ``smooth`` seconds everywhere."""
    return _gaussian_mean(O, times, np.full(len(O), float(smooth)))


def adaptive(O: NDArray, times: NDArray, smooth: float) -> NDArray[np.float64]:
    """A Gaussian window narrowed where the slow component of the motion turns fast:
    σ_t = smooth / (1 + |ω_t| / 30°/s), itself averaged over 5 frames."""
    slow = gaussian(O, times, smooth)
    speed = np.degrees(angular_speed(slow, times))
    sigma = smooth / (1.0 + speed / ADAPTIVE_REF_DEG_S)
    sigma = np.convolve(np.pad(sigma, 2, mode="edge"), np.ones(5) / 5, mode="valid")
    return _gaussian_mean(O, times, sigma)


def lock(O: NDArray, times: NDArray, smooth: float) -> NDArray[np.float64]:
    """One orientation for the whole clip, as on a tripod: the mean one, which needs
    less zoom than holding the first."""
    mean = so3.exp_so3(so3.log_so3(O @ O[0].T).mean(axis=0)) @ O[0]
    return np.broadcast_to(mean, O.shape).copy()


# The registry: a method's name → S(O, times, smooth). Adding one is a function here.
Smoother = Callable[[NDArray, NDArray, float], NDArray]
METHODS: dict[str, Smoother] = {"adaptive": adaptive, "gaussian": gaussian, "lock": lock}


def smooth_orientations(
    O: NDArray, times: NDArray, smooth: float = 0.5, method: str = "adaptive"
) -> NDArray[np.float64]:
    """The smoothed path S_t for orientations O_t (N, 3, 3) at ``times`` (s)."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {tuple(METHODS)}, got {method!r}")
    O = np.asarray(O, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    if len(O) < 2 and method != "lock":
        return O.copy()
    return METHODS[method](O, times, smooth)


def orientations_from_rotations(R: NDArray) -> NDArray[np.float64]:
    """O_0 = I and O_{t+1} = R_t O_t, for frame-to-frame rotations R_t (N-1, 3, 3)."""
    O = np.empty((len(R) + 1, 3, 3))
    O[0] = np.eye(3)
    for k, r in enumerate(R):
        O[k + 1] = r @ O[k]
    return O
