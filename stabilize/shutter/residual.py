"""The image motion a rotation leaves, measured again once the rows are dated.

Pass 1 measured each pair's remaining similarity against the whole-frame rotation, on
flow skewed by the rolling shutter (:mod:`stabilize.motion.residual`): part of that skew
went into the similarity, which the row corrections then undo a second time. With the
turns D_k(y) of each frame's rows against its middle row, every kept flow vector is
taken to the middle rows' cameras first: a point seen at row y of frame k, ray p, and at
row y' of frame k+1, ray p', leaves

    r = π(D_{k+1}(y')ᵀ p') - π(R_k D_k(y)ᵀ p),

with R_k the turn between the middle rows, and the background's similarity is fitted to
that, as in pass 1.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stabilize.motion.residual import GATE_PX, background_similarity, normalised
from stabilize.motion.track import Samples
from stabilize.warp.rolling import RollingShutter

CHUNK = 16  # pairs whose per-vector turns are held at once


def rectified_residual(
    samples: Samples,
    R: NDArray,
    rolling: RollingShutter,
    focal: float,
    height: int,
    gate: float = GATE_PX,
) -> NDArray[np.float64]:
    """The similarity (N-1, 4) each middle-row rotation R (N-1, 3, 3) leaves, from the
    kept ``samples``; ``focal`` (px) and ``height`` (px) of the input frames; ``gate``
    (px at the flow's size) as pass 1's (:func:`stabilize.motion.residual.gate_px`)."""
    f = focal * samples.scale
    x, y = samples.x, samples.y
    ray = np.stack([x, y, np.full_like(x, f)], 1)
    to_input = height / samples.height  # flow rows → input rows (pixel centres)
    out = []
    fine_u, fine_v = samples.fine  # the refined vectors, as pass 1 measured them
    for first in range(0, len(samples.u), CHUNK):
        part = slice(first, first + CHUNK)
        u, v = fine_u[part].astype(np.float64), fine_v[part].astype(np.float64)
        k = np.arange(first, first + len(u))
        start = rolling.at(k, (samples.rows + 0.5) * to_input - 0.5)
        end = rolling.at(k + 1, (samples.rows + v + 0.5) * to_input - 0.5)
        seen = np.stack([x + u, y + v, np.full_like(u, f)], -1)
        before = (start.swapaxes(-1, -2) @ ray[..., None])[..., 0]  # D_k(y)ᵀ p
        after = (end.swapaxes(-1, -2) @ seen[..., None])[..., 0]  # D_{k+1}(y')ᵀ p'
        turned = (R[part][:, None] @ before[..., None])[..., 0]
        (ax, ay), (tx, ty) = normalised(after), normalised(turned)
        out.append(background_similarity(x, y, ax - tx, ay - ty, samples.voting[part], f, gate))
    return np.concatenate(out) if out else np.zeros((0, 4))
