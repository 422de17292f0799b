"""Regular sampling of a dense flow field, and input validation."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class SampleGrid:
    """Pixel positions sampled every ``step`` pixels, centred in an (H, W) field.

    ``rows`` and ``cols`` index the field; ``x`` and ``y`` are the flattened
    sample positions relative to the principal point (what the motion models use).
    """

    size: tuple[int, int]
    rows: NDArray[np.intp]
    cols: NDArray[np.intp]
    x: NDArray[np.float64]
    y: NDArray[np.float64]

    @property
    def shape(self) -> tuple[int, int]:
        return (len(self.rows), len(self.cols))


def sample_grid(size: tuple[int, int], step: int, center: tuple[float, float]) -> SampleGrid:
    """Grid of every ``step``-th pixel, with equal margins on both sides."""
    h, w = size
    if step < 1:
        raise ValueError(f"step must be a positive number of pixels, got {step}")
    if step > min(h, w):
        raise ValueError(f"step {step} is larger than the flow field {w}x{h}")
    rows = _centred(h, step)
    cols = _centred(w, step)
    yy, xx = np.meshgrid(rows.astype(np.float64), cols.astype(np.float64), indexing="ij")
    return SampleGrid(size, rows, cols, (xx - center[0]).ravel(), (yy - center[1]).ravel())


def _centred(n: int, step: int) -> NDArray[np.intp]:
    count = n // step
    start = (n - 1 - (count - 1) * step) // 2
    return start + step * np.arange(count)


def check_flows(flows: NDArray, size: tuple[int, int], *, stacked: bool) -> NDArray:
    """Validate a flow field (H, W, 2) or a stack (N, H, W, 2); return it as an array."""
    flows = np.asarray(flows)
    want = ("N", *size, 2) if stacked else (*size, 2)
    ndim = 4 if stacked else 3
    if flows.ndim != ndim or flows.shape[-3:] != (*size, 2):
        raise ValueError(
            f"flow must have shape {want} (H, W from the estimator's size), got {flows.shape}"
        )
    if not np.issubdtype(flows.dtype, np.floating):
        raise ValueError(f"flow must be a floating-point array, got dtype {flows.dtype}")
    return flows


def sample_flows(flows: NDArray, grid: SampleGrid) -> tuple[NDArray, NDArray, NDArray]:
    """u, v (N, M) float64 at the grid, and the mask of finite vectors."""
    picked = flows[..., grid.rows[:, None], grid.cols[None, :], :]
    picked = picked.reshape(*flows.shape[:-3], -1, 2).astype(np.float64)
    u, v = picked[..., 0], picked[..., 1]
    valid = np.isfinite(u) & np.isfinite(v)
    return np.where(valid, u, 0.0), np.where(valid, v, 0.0), valid
