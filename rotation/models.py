"""The two motion models: which rotations can produce one flow vector.

Pixel positions (x, y) are relative to the principal point, f is the focal length in
pixels, and a flow vector (u, v) moves (x, y) to (x + u, y + v).

Rotations are voted on as ω = (A, B, C), the Longuet-Higgins rotational velocity of
the camera. Under CONVENTIONS.md that is the small-angle rotation vector of the
camera's own motion, R_tᵀ, so R_t = exp(-[ω]×).

**Longuet-Higgins** (paper §3.1.2). For a purely rotational field

    u = A xy/f - B (f² + x²)/f + C y
    v = A (f² + y²)/f - B xy/f - C x

Two planes in (A, B, C) meet in a straight line. Its direction n_u × n_v is
parallel to (x/f, y/f, 1), the pixel's own viewing ray (turning about the ray does
not move the pixel), and it crosses C = 0 at

    A₀ = (-xy u + (f² + x²) v) / (f (f² + x² + y²))
    B₀ = (-(f² + y²) u + xy v) / (f (f² + x² + y²)).

**Perspective** (paper §3.1.1). With unit rays P (pixel) and Q (pixel + flow), every
rotation with R P = Q is R(θ) = Rot(Q, θ) R_{P→Q}: a curve in SO(3) that is sampled.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def lh_line(x: float, y: float, u: float, v: float, f: float) -> tuple:
    """Point (A₀, B₀, 0) and direction (x/f, y/f, 1) of one vector's compatible line."""
    det = f * (f * f + x * x + y * y)
    a0 = (-x * y * u + (f * f + x * x) * v) / det
    b0 = (-(f * f + y * y) * u + x * y * v) / det
    return a0, b0, x / f, y / f


@njit(cache=True)
def perspective_curve(
    px: float, py: float, qx: float, qy: float, f: float, thetas: np.ndarray, out: np.ndarray
) -> None:
    """ω(θ) = -log(Rot(Q, θ) R_{P→Q}) for each θ, written into out (len(θ), 3).

    Quaternions are expanded into scalars: this runs for every sample of every
    vector, and small temporary arrays would dominate its cost.
    """
    n_p = math.sqrt(px * px + py * py + f * f)
    n_q = math.sqrt(qx * qx + qy * qy + f * f)
    P0, P1, P2 = px / n_p, py / n_p, f / n_p
    Q0, Q1, Q2 = qx / n_q, qy / n_q, f / n_q
    # R_{P→Q}: about P × Q by the angle between the rays.
    c0, c1, c2 = P1 * Q2 - P2 * Q1, P2 * Q0 - P0 * Q2, P0 * Q1 - P1 * Q0
    s = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    half = 0.5 * math.atan2(s, P0 * Q0 + P1 * Q1 + P2 * Q2)
    bw = math.cos(half)
    k = math.sin(half) / s if s > 1e-15 else 0.0
    bx, by, bz = c0 * k, c1 * k, c2 * k
    for i in range(thetas.shape[0]):
        aw = math.cos(0.5 * thetas[i])
        sa = math.sin(0.5 * thetas[i])
        ax, ay, az = Q0 * sa, Q1 * sa, Q2 * sa
        # Hamilton product a ⊗ b, then the rotation vector of the result.
        w = aw * bw - ax * bx - ay * by - az * bz
        x = aw * bx + ax * bw + ay * bz - az * by
        y = aw * by - ax * bz + ay * bw + az * bx
        z = aw * bz + ax * by - ay * bx + az * bw
        if w < 0.0:
            w, x, y, z = -w, -x, -y, -z
        norm = math.sqrt(x * x + y * y + z * z)
        scale = 2.0 * math.atan2(norm, w) / norm if norm > 1e-12 else 2.0
        out[i, 0] = -scale * x
        out[i, 1] = -scale * y
        out[i, 2] = -scale * z
