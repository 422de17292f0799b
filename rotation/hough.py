"""Frame-to-frame camera rotation by a Hough transform on SO(3) (ICCV 2023), refined.

Every flow vector allows a one-parameter family of rotations (a straight line under
the Longuet-Higgins model, a curve under exact perspective, see :mod:`rotation.models`).
Each family votes for every rotation bin it crosses; distant static points agree on
one bin, while moving people, parallax and bad flow scatter their votes. The fullest
bin is the answer, with no RANSAC.

Beyond the paper:

* **Refinement.** The bin's centre is only within √3/2 bins of the truth, so the
  rotation is refitted to the inliers with the exact homography K R K⁻¹ by
  Gauss-Newton (:mod:`rotation.refine`).
* **Coarse to fine.** A search range that would need more than ``FINE_LIMIT`` bins
  per half-axis first votes with coarse bins; the flow is then de-rotated by the
  (refined) coarse answer, and fine bins vote on what is left. De-rotating also keeps
  the Longuet-Higgins model, a small-angle model, accurate for fast pans.
* **Bad values.** Non-finite vectors are skipped; too few valid vectors give the
  identity with support 0.

Example:
    >>> import numpy as np
    >>> from rotation import HoughEstimator, so3
    >>> from rotation.synthetic import rotation_flow
    >>> R = so3.exp_so3([0.0, 0.01, 0.0])
    >>> flow = rotation_flow(R, focal=413.75, size=(270, 480))
    >>> est = HoughEstimator((270, 480), 413.75).estimate(flow)
    >>> bool(so3.angular_error_deg(est.matrix, R) < 1e-3)
    True
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import get_num_threads, njit
from numpy.typing import NDArray

from rotation.camera import default_center
from rotation.models import lh_line, perspective_curve
from rotation.refine import refine, rodrigues, rotate_ray
from rotation.result import RotationEstimate
from rotation.sampling import check_flows, sample_flows, sample_grid
from rotation.so3 import log_so3
from rotation.voting import (
    BEST,
    BEST_COUNT,
    bin_center,
    bins_per_axis,
    cast,
    lh_line_hits_bin,
    point_bins,
    reset,
    unravel,
    vote_lh_line,
)

MODELS = ("longuet-higgins", "perspective")
COARSE_FACTOR = 8  # a coarse bin is this many fine bins wide...
COARSE_BINS = 16  # ...unless that gives more than this many coarse bins per half-axis
MIN_VECTORS = 8  # fewer valid vectors than this cannot outvote noise
REFINE_GATE_BINS = 4.0  # refinement starts with vectors within this many bins' pixels
CURVE_OVERSAMPLING = 3  # perspective curve samples per bin length


def search_levels(bin_deg: float, max_deg: float) -> NDArray[np.float64]:
    """(bin size, half range) in radians of each voting pass, coarse to fine."""
    if bin_deg <= 0 or max_deg <= 0:
        raise ValueError("bin_deg and max_deg must be positive")
    coarse = max(COARSE_FACTOR * bin_deg, max_deg / COARSE_BINS)
    if coarse >= max_deg:
        return np.radians([[bin_deg, max_deg]])
    return np.radians([[coarse, max_deg], [bin_deg, 1.5 * coarse]])


class HoughEstimator:
    """Rotation estimator for flow fields of one size and one camera.

    Args:
        size: (H, W) of the flow fields.
        focal: focal length in pixels at that size.
        center: principal point (cx, cy); default ((W-1)/2, (H-1)/2).
        step: sample a flow vector every ``step`` pixels (15 gives 576 at 480×270).
        bin_deg: edge of a rotation bin in degrees.
        max_deg: search rotations up to this angle about each axis, in degrees.
            Above about 4.5° a coarse-to-fine search is used, so 15° pans are found.
        model: ``"longuet-higgins"`` (lines, fast) or ``"perspective"`` (exact curves).
        refine: refit the rotation to the inliers beyond the bin's resolution.

    Everything that depends only on geometry (sample positions, line coefficients,
    the vote accumulator) is set up here, once. An estimator is safe to share
    between threads; calls on one estimator run one at a time.
    """

    def __init__(
        self,
        size: Sequence[int],
        focal: float,
        *,
        center: Sequence[float] | None = None,
        step: int = 15,
        bin_deg: float = 0.057,
        max_deg: float = 4.0,
        model: str = "longuet-higgins",
        refine: bool = True,
    ) -> None:
        if len(size) != 2 or min(size) < 1:
            raise ValueError(f"size must be (H, W) in pixels, got {tuple(size)}")
        if not (math.isfinite(focal) and focal > 0):
            raise ValueError(f"focal must be a positive number of pixels, got {focal}")
        if model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, got {model!r}")
        self.size = (int(size[0]), int(size[1]))
        self.focal = float(focal)
        self.center = default_center(self.size) if center is None else tuple(map(float, center))
        self.model = model
        self.refine = bool(refine)
        self.levels = search_levels(bin_deg, max_deg)
        self.grid = sample_grid(self.size, step, self.center)
        self._model_code = MODELS.index(model)
        self._n_max = max(bins_per_axis(h, s) for s, h in self.levels)
        self._touched_len = touched_capacity(len(self.grid.x), self._n_max, self.levels)
        self._acc = np.zeros(self._n_max**3, np.int32)
        self._touched = np.empty(self._touched_len, np.int64)
        self._lock = threading.Lock()

    def estimate(self, flow: NDArray) -> RotationEstimate:
        """Rotation R_t of one (H, W, 2) forward flow field."""
        flow = check_flows(flow, self.size, stacked=False)
        u, v, valid = sample_flows(flow, self.grid)
        with self._lock:
            R, count, inliers = estimate_field(
                *self._field_args(u, v, valid), self._acc, self._touched
            )
        return self._result(R, log_so3(R), count, inliers, valid)

    def estimate_many(self, flows: NDArray) -> list[RotationEstimate]:
        """Rotations of a stack (N, H, W, 2), in parallel over the available cores.

        The fields are dealt out in interleaved chunks, two per thread, each with an
        accumulator of its own; the kernel releases the GIL, so plain threads run the
        chunks side by side. (A numba ``prange`` kernel did the same as fast, but took
        twice as long to compile on the first run: 21 s against 11 s.)
        """
        return self.estimate_samples(*self.samples(flows))

    def samples(self, flows: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """The vectors the estimator reads from a stack (N, H, W, 2): u, v (N, M) at the
        sample grid (:attr:`grid`), and their validity. About 5 KB per field, so a
        clip's can be kept and estimated again (another focal length, other bands)."""
        return sample_flows(check_flows(flows, self.size, stacked=True), self.grid)

    def estimate_samples(self, u: NDArray, v: NDArray, valid: NDArray) -> list[RotationEstimate]:
        """Rotations of sampled fields (N, M) (:meth:`samples`); what
        :meth:`estimate_many` does after sampling."""
        # row-major, whatever the caller's layout: a field's row is then contiguous, and
        # the kernel is loaded for one signature (a second cost 25–50 ms a process)
        u, v = np.ascontiguousarray(u, np.float64), np.ascontiguousarray(v, np.float64)
        valid = np.ascontiguousarray(valid, np.bool_)
        n = len(u)
        threads = max(1, min(n, get_num_threads()))
        chunks = min(n, 2 * threads)
        Rs = np.empty((n, 3, 3))
        counts = np.zeros(n, np.int64)
        inliers = np.zeros(u.shape, np.bool_)
        args = self._field_args(u, v, valid)

        def run(c: int) -> None:
            acc = np.zeros(self._n_max**3, np.int32)
            touched = np.empty(self._touched_len, np.int64)
            picks = np.arange(c, n, chunks)
            estimate_chunk(*args, acc, touched, picks, Rs, counts, inliers)

        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(run, range(chunks)))
        # the rotation vectors in one call: one per estimate cost 0.15 ms each, 0.6 s of
        # a 1080p 10 s clip's pass 1 (12 bands a pair)
        rotvecs = log_so3(Rs)
        return [
            self._result(*item) for item in zip(Rs, rotvecs, counts, inliers, valid, strict=True)
        ]

    def _field_args(self, u: NDArray, v: NDArray, valid: NDArray) -> tuple:
        """The kernels' leading arguments: samples, flow, focal length, search, model."""
        x, y = self.grid.x, self.grid.y
        return x, y, u, v, valid, self.focal, self.levels, self._model_code, self.refine

    def _result(
        self, R: NDArray, rotvec: NDArray, count: int, inliers: NDArray, valid: NDArray
    ) -> RotationEstimate:
        n_valid = int(valid.sum())
        support = count / n_valid if n_valid >= MIN_VECTORS else 0.0
        return RotationEstimate(R, rotvec, float(support), inliers.reshape(self.grid.shape))


def warm_up() -> None:
    """Load the estimator's kernels now, from numba's cache (or compiled, the first time).

    A process's first kernel call also sets numba itself up: 0.2 s before the first
    frame was decoded (1080p, 10 s, this 2-core machine), and the main kernel's load
    50 ms more. Called on a thread while FFmpeg probes the file, that time is spent
    waiting on FFmpeg instead."""
    estimator = HoughEstimator((16, 16), 16.0, step=8)
    m = len(estimator.grid.x)
    estimator.estimate_samples(np.zeros((1, m)), np.zeros((1, m)), np.zeros((1, m), np.bool_))


def estimate(flow: NDArray, focal: float, **options) -> RotationEstimate:
    """One-call convenience: ``HoughEstimator(flow.shape[:2], focal, **options).estimate(flow)``."""
    flow = np.asarray(flow)
    if flow.ndim != 3:
        raise ValueError(f"flow must have shape (H, W, 2), got {flow.shape}")
    return HoughEstimator(flow.shape[:2], focal, **options).estimate(flow)


def touched_capacity(n_vectors: int, n_max: int, levels: NDArray) -> int:
    """Upper bound on distinct bins one field can touch (for the reset list)."""
    per_line = 3 * n_max + 3
    curve_samples = max(curve_thetas(s, h).shape[0] for s, h in levels)
    return n_vectors * max(per_line, curve_samples) + 16


@njit(cache=True)
def curve_thetas(bin_size: float, half_range: float) -> np.ndarray:
    """Angles θ at which a perspective curve is sampled: wide enough to span the cube."""
    theta_max = math.sqrt(3.0) * half_range + bin_size
    n = int(math.ceil(2.0 * theta_max * CURVE_OVERSAMPLING / bin_size)) + 1
    return np.linspace(-theta_max, theta_max, n)


@njit(cache=True)
def estimate_field(x, y, u, v, valid, f, levels, model, do_refine, acc, touched):
    """Vote, pass by pass, then refine. Returns (R, inlier count, inlier mask)."""
    m = x.shape[0]
    inliers = np.zeros(m, np.bool_)
    if valid.sum() < MIN_VECTORS:
        return np.eye(3), 0, inliers
    state = np.zeros(3, np.int64)
    qx = x + u
    qy = y + v
    R = np.eye(3)
    xp = x.copy()
    yp = y.copy()
    count = 0
    for level in range(levels.shape[0]):
        s, half = levels[level, 0], levels[level, 1]
        n = bins_per_axis(half, s)
        if level > 0:
            derotate(x, y, f, R, xp, yp)
        if model == 0:
            vote_lines(xp, yp, qx, qy, valid, f, s, n, acc, touched, state)
        else:
            vote_curves(xp, yp, qx, qy, valid, f, s, half, n, acc, touched, state)
        if state[BEST_COUNT] == 0:
            reset(acc, touched, state)
            return np.eye(3), 0, np.zeros(m, np.bool_)
        b = unravel(state[BEST], n)
        reset(acc, touched, state)
        if model == 0:
            inliers = line_inliers(xp, yp, qx, qy, valid, f, s, n, b)
        else:
            inliers = curve_inliers(xp, yp, qx, qy, valid, f, s, half, n, b)
        count = int(inliers.sum())
        R = rodrigues(-bin_center(b, n, s)) @ R
    if do_refine:
        R = refine(x, y, qx, qy, f, R, valid, REFINE_GATE_BINS * f * levels[-1, 0])
    return R, count, inliers


@njit(cache=True)
def derotate(x, y, f, R, xp, yp) -> None:
    """Where each sample lands under R alone: π(R (x, y, f)), written into xp, yp."""
    for i in range(x.shape[0]):
        X0, X1, X2 = rotate_ray(R, x[i], y[i], f)
        X2 = max(X2, 1e-9)
        xp[i] = f * X0 / X2
        yp[i] = f * X1 / X2


@njit(cache=True)
def line_in_bins(px, py, qx, qy, f, s, n) -> tuple:
    """One Longuet-Higgins line in bin coordinates: (a0, b0, da, db), parametrised by C."""
    a0, b0, da, db = lh_line(px, py, qx - px, qy - py, f)
    return a0 / s + 0.5 * n, b0 / s + 0.5 * n, da, db


@njit(cache=True)
def vote_lines(xp, yp, qx, qy, valid, f, s, n, acc, touched, state) -> None:
    for i in range(xp.shape[0]):
        if valid[i]:
            a0, b0, da, db = line_in_bins(xp[i], yp[i], qx[i], qy[i], f, s, n)
            vote_lh_line(a0, b0, da, db, n, acc, touched, state)


@njit(cache=True)
def line_inliers(xp, yp, qx, qy, valid, f, s, n, b) -> np.ndarray:
    out = np.zeros(xp.shape[0], np.bool_)
    for i in range(xp.shape[0]):
        if valid[i]:
            a0, b0, da, db = line_in_bins(xp[i], yp[i], qx[i], qy[i], f, s, n)
            out[i] = lh_line_hits_bin(a0, b0, da, db, n, b)
    return out


@njit(cache=True)
def vote_curves(xp, yp, qx, qy, valid, f, s, half, n, acc, touched, state) -> None:
    thetas = curve_thetas(s, half)
    bins = np.empty(thetas.shape[0], np.int64)
    pts = np.empty((thetas.shape[0], 3))
    for i in range(xp.shape[0]):
        if valid[i]:
            perspective_curve(xp[i], yp[i], qx[i], qy[i], f, thetas, pts)
            for k in range(point_bins(pts, n, s, bins)):
                cast(acc, touched, state, bins[k])


@njit(cache=True)
def curve_inliers(xp, yp, qx, qy, valid, f, s, half, n, b) -> np.ndarray:
    thetas = curve_thetas(s, half)
    bins = np.empty(thetas.shape[0], np.int64)
    target = (b[0] * n + b[1]) * n + b[2]
    out = np.zeros(xp.shape[0], np.bool_)
    pts = np.empty((thetas.shape[0], 3))
    for i in range(xp.shape[0]):
        if valid[i]:
            perspective_curve(xp[i], yp[i], qx[i], qy[i], f, thetas, pts)
            count = point_bins(pts, n, s, bins)
            out[i] = np.any(bins[:count] == target)
    return out


@njit(cache=True, nogil=True)
def estimate_chunk(
    x, y, u, v, valid, f, levels, model, do_refine, acc, touched, picks, Rs, counts, inliers
) -> None:
    """estimate_field for the fields ``picks`` of a stack, with one accumulator, into
    Rs, counts and inliers; without the GIL, so that threads run chunks side by side.

    Copied element by element: an array assigned to a slice (``Rs[i] = R``) makes numba
    compile the shape-mismatch error's formatting, 2.8 s of a fresh install's first
    compile, then 20 s."""
    for i in picks:
        R, count, mask = estimate_field(
            x, y, u[i], v[i], valid[i], f, levels, model, do_refine, acc, touched
        )
        for r in range(3):
            for c in range(3):
                Rs[i, r, c] = R[r, c]
        counts[i] = count
        for j in range(mask.shape[0]):
            inliers[i, j] = mask[j]
