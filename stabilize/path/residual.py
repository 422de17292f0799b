"""The 2-D path: the image motion the rotation leaves, chained, smoothed and undone.

Each pair's residual similarity (:mod:`stabilize.motion.residual`) maps frame t's
derotated image to frame t+1's, A_t = [[1+a, -b, dx], [b, 1+a, dy], [0, 0, 1]] in
normalised coordinates. Chained, M_{t+1} = A_t M_t is where the background's content
sits in frame t; as a path it is q_t = (tx, ty, θ, ln s). The components the motion
model names are smoothed, the others kept, into q̃_t, and the frame is moved by

    D_t = M(q̃_t) M(q_t)⁻¹

after its rotation, in the same warp: K' D_t C_t K⁻¹.

The smoothing is a Gaussian-weighted local line (σ = ``smooth`` s), not a Gaussian
mean: a walk's steady drift is a line, which the local line follows to the clip's last
frame, where a truncated mean lags by up to 0.4 σ·speed (on a 2 s walk at 30°, 9% of the
frame's width at the ends, all of it crop).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.path.smoothing import gaussian_band

# The registry: a motion model's name → the components of q it compensates. Adding
# one (a dominant plane's homography, say) is a line here and its parameters in pass 1.
MOTION_MODELS: dict[str, tuple[int, ...]] = {
    "rotation": (),
    "translation": (0, 1),
    "similarity": (0, 1, 2, 3),
}


def step_matrices(residual: NDArray) -> NDArray[np.float64]:
    """A_t (n, 3, 3) of residual similarities (dx, dy, a, b) (n, 4)."""
    dx, dy, a, b = np.asarray(residual, np.float64).T
    A = np.zeros((len(dx), 3, 3))
    A[:, 0, 0] = A[:, 1, 1] = 1.0 + a
    A[:, 0, 1], A[:, 1, 0] = -b, b
    A[:, 0, 2], A[:, 1, 2], A[:, 2, 2] = dx, dy, 1.0
    return A


def path_of(residual: NDArray) -> NDArray[np.float64]:
    """q_t = (tx, ty, θ, ln s) (N, 4) of the chain M_0 = I, M_{t+1} = A_t M_t."""
    A = step_matrices(residual)
    M = np.empty((len(A) + 1, 3, 3))
    M[0] = np.eye(3)
    for k, step in enumerate(A):
        M[k + 1] = step @ M[k]
    theta = np.arctan2(M[:, 1, 0], M[:, 0, 0])
    return np.stack([M[:, 0, 2], M[:, 1, 2], theta, np.log(np.hypot(M[:, 0, 0], M[:, 1, 0]))], 1)


def matrices(q: NDArray) -> NDArray[np.float64]:
    """M(q) (N, 3, 3) of paths q = (tx, ty, θ, ln s) (N, 4)."""
    tx, ty, theta, log_s = np.asarray(q, np.float64).T
    s = np.exp(log_s)
    M = np.zeros((len(tx), 3, 3))
    M[:, 0, 0] = M[:, 1, 1] = s * np.cos(theta)
    M[:, 1, 0] = s * np.sin(theta)
    M[:, 0, 1] = -M[:, 1, 0]
    M[:, 0, 2], M[:, 1, 2], M[:, 2, 2] = tx, ty, 1.0
    return M


def local_line(values: NDArray, times: NDArray, sigma: float) -> NDArray[np.float64]:
    """Each column of ``values`` (N, k) smoothed by a Gaussian-weighted line fitted
    around every frame (σ in s, cut at 4σ): exact on lines, up to the clip's ends.

    >>> t = np.arange(30) / 30.0
    >>> bool(np.allclose(local_line(np.c_[2 * t + 1], t, 0.2)[:, 0], 2 * t + 1))
    True
    """
    values = np.asarray(values, np.float64)
    times = np.asarray(times, np.float64)
    if len(values) < 3:
        return values.copy()
    g = gaussian_band(times, max(sigma, 1e-3))
    rows = np.repeat(np.arange(len(times)), np.diff(g.indptr))
    dt = times[g.indices] - times[rows]
    s0 = g.sum(axis=1)
    s1 = g @ times - times * s0
    moment = g.copy()
    moment.data = g.data * dt * dt
    s2 = moment.sum(axis=1)
    t0 = g @ values
    t1 = g @ (times[:, None] * values) - times[:, None] * t0
    det = s0 * s2 - s1 * s1
    flat = det <= 1e-12 * np.maximum(s0 * s2, 1e-300)  # one frame in the window
    safe = np.where(flat, 1.0, det)
    line = (s2[:, None] * t0 - s1[:, None] * t1) / safe[:, None]
    return np.where(flat[:, None], t0 / s0[:, None], line)


def smooth_path(
    q: NDArray, times: NDArray, smooth: float, model: str, hold: bool = False
) -> NDArray[np.float64]:
    """q̃ (N, 4): the model's components of q smoothed by :func:`local_line` (held at
    their mean with ``hold``, as on a tripod), the others as they are. The scale's path
    is lowered by a constant (which is no motion) until no frame's correction zooms in:
    the zoom that hides the borders then accounts for all the cropping, within the
    budget."""
    if model not in MOTION_MODELS:
        raise ValueError(f"motion must be one of {tuple(MOTION_MODELS)}, got {model!r}")
    q = np.asarray(q, np.float64)
    out = q.copy()
    parts = list(MOTION_MODELS[model])
    if parts:
        if hold:
            out[:, parts] = out[:, parts].mean(axis=0)
        else:
            out[:, parts] = local_line(out[:, parts], times, smooth)
    if 3 in parts:  # never zoom in: the crop budget (the zoom) bounds the whole crop
        out[:, 3] -= max(0.0, float((out[:, 3] - q[:, 3]).max(initial=0.0)))
    return out


def corrections(raw: NDArray, smooth: NDArray) -> NDArray[np.float64]:
    """D_t = M(q̃_t) M(q_t)⁻¹ (N, 3, 3), normalised coordinates."""
    return matrices(smooth) @ np.linalg.inv(matrices(raw))
