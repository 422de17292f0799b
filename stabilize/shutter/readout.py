"""The rolling-shutter readout from the video alone.

Each band of a frame pair saw the camera turn over its own stretch of time,
t_k + r·y_b to t_{k+1} + r·y_b (:mod:`.attitude`). Only the right readout r lets one
continuous attitude explain every band of every pair at once, so r is the minimiser of
the robust (Cauchy) cost of that fit: a grid over -0.2..1.2 frame intervals, then a
golden-section search around the best point. Its uncertainty comes from the cost's
curvature at the minimum, the weights held: σ_r² = σ²/(½ Q''), with Q(r) the weighted
squared residual and σ² its value per degree of freedom.

Smooth, slow motion shows every band the same turn whatever r is; the estimate is then
refused. An estimate that cannot be told from 0 is a global shutter, and nothing is
corrected.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro.sync import golden_section
from stabilize.motion.track import VisualTrack
from stabilize.shutter.attitude import Bands, Spline, fit_attitude, knots_for
from stabilize.video.decode import frame_interval

GRID = 29  # readouts tried across -0.2..1.2 frame intervals
MAX_SEARCH_PAIRS = 900  # pairs the readout is searched on (30 s at 30 fps)
MIN_PAIRS = 20  # pairs with three usable bands, fewest that date the rows
MAX_STDERR = 0.06  # of a frame interval (2 ms at 30 fps): a less certain readout is refused
SIGNIFICANT = 3.0  # an estimate within this many σ of 0, or under MIN_READOUT, is 0
MIN_READOUT = 0.001  # s


@dataclass(frozen=True)
class Readout:
    """The readout the warp uses (s; 0: none corrected) and where it came from:
    ``estimated``, ``given``, ``off`` or ``refused`` (then ``reason`` says why)."""

    seconds: float
    source: str
    estimate: float | None = None  # s, the fit's value, where one was made
    stderr: float | None = None  # s
    reason: str = ""

    def summary(self) -> dict:
        """The readout as JSON values, in ms."""
        return {
            "readout_ms": 1000.0 * float(self.seconds),
            "source": self.source,
            "estimate_ms": _ms(self.estimate),
            "stderr_ms": _ms(self.stderr),
            "reason": self.reason,
        }

    def describe(self) -> str:
        """One line for the summary."""
        if self.source in ("given", "off"):
            return f"{1000 * self.seconds:.1f} ms ({self.source})"
        if self.estimate is None:
            return f"not corrected ({self.reason})"
        fit = f"{1000 * self.estimate:.1f} ± {1000 * self.stderr:.1f} ms"
        if self.source == "refused":
            return f"not corrected: {fit}, {self.reason}"
        if not self.seconds:
            return f"global shutter ({fit})"
        return f"{fit} (estimated)"


def _ms(seconds: float | None) -> float | None:
    return None if seconds is None else 1000.0 * float(seconds)


def readout_for(option: float | str, track: VisualTrack) -> tuple[Readout, Spline | None]:
    """The readout ``--rolling-shutter`` asks for ('auto', 'off' or ms), and the attitude
    fitted at it (None where nothing is corrected)."""
    if option == "off":
        return Readout(0.0, "off"), None
    if option == "auto":
        return estimate_readout(track)
    seconds = float(option) / 1000.0
    if not seconds:
        return Readout(0.0, "given"), None
    bands = Bands.of(track)
    knots = knots_for(track.times)
    spline, _, _ = fit_attitude(bands, seconds, knots, cauchy_scale(bands, seconds, knots))
    return Readout(seconds, "given"), spline


def estimate_readout(track: VisualTrack) -> tuple[Readout, Spline | None]:
    """The readout of a track with band rotations, and the attitude fitted at it (None
    where refused or 0). A long clip's readout is searched on its ``MAX_SEARCH_PAIRS``
    most shaking consecutive pairs (the search's time grows with the length: 1.5 s for a
    minute), and the attitude is then fitted to the whole clip once."""
    frame = frame_interval(track.times)
    first = _most_shaking(track, MAX_SEARCH_PAIRS)
    searched = track.pairs(first, first + MAX_SEARCH_PAIRS) if first is not None else track
    bands = Bands.of(searched)
    per_pair = bands.usable.reshape(len(searched.bands), -1).sum(0)
    if int((per_pair >= 3).sum()) < MIN_PAIRS:
        reason = "too few frames with texture across their height"
        return Readout(0.0, "refused", reason=reason), None
    knots = knots_for(searched.times)
    scale = cauchy_scale(bands, 0.5 * frame, knots)

    def cost(r: float) -> float:
        _, e, _ = fit_attitude(bands, r, knots, scale)
        return float(np.sum(bands.usable * np.log1p((e / scale) ** 2)))

    grid = np.linspace(-0.2 * frame, 1.2 * frame, GRID)
    best = int(np.argmin([cost(r) for r in grid]))
    step = grid[1] - grid[0]
    r = golden_section(cost, grid[max(best - 1, 0)], grid[min(best + 1, GRID - 1)], 1e-2 * step)
    stderr = curvature_stderr(bands, r, knots, scale, 0.05 * frame)
    if first is not None:  # the attitude of the whole clip
        bands, knots = Bands.of(track), knots_for(track.times)
        scale = cauchy_scale(bands, r, knots)
    return decide(bands, r, stderr, frame, knots, scale)


def _most_shaking(track: VisualTrack, n: int) -> int | None:
    """The first of the n consecutive pairs whose rotations change the most from pair to
    pair (what dates the bands), or None for a track of no more pairs than that."""
    if len(track.rotations) <= n:
        return None
    change = np.linalg.norm(np.diff(so3.log_so3(track.rotations), axis=0), axis=1)
    return int(np.argmax(np.convolve(change, np.ones(n - 1), mode="valid")))


def cauchy_scale(bands: Bands, readout: float, knots: NDArray) -> float:
    """The Cauchy loss's scale: the residuals' robust spread in a least-squares fit."""
    _, error, _ = fit_attitude(bands, readout, knots, scale=1.0, steps=1)
    return 1.4826 * float(np.median(error[bands.usable])) + 1e-12


def decide(
    bands: Bands, r: float, stderr: float, frame: float, knots: NDArray, scale: float
) -> tuple[Readout, Spline | None]:
    """Refuse an uncertain or impossible readout, call a negligible one 0."""
    if not stderr <= MAX_STDERR * frame:
        return Readout(0.0, "refused", r, stderr, "the motion does not pin it down"), None
    if r >= 1.05 * frame:
        return Readout(0.0, "refused", r, stderr, "longer than a frame interval"), None
    if r <= -0.1 * frame:
        reason = "negative: a bottom-to-top readout is not modelled"
        return Readout(0.0, "refused", r, stderr, reason), None
    if r < max(SIGNIFICANT * stderr, MIN_READOUT):
        return Readout(0.0, "estimated", r, stderr, "no rolling shutter measured"), None
    spline, _, _ = fit_attitude(bands, r, knots, scale)
    return Readout(r, "estimated", r, stderr), spline


def curvature_stderr(bands: Bands, r: float, knots: NDArray, scale: float, h: float) -> float:
    """σ_r from the curvature of the weighted squared residual Q at r, weights held."""
    _, _, w = fit_attitude(bands, r, knots, scale)

    def Q(x: float) -> float:
        _, e, _ = fit_attitude(bands, x, knots, scale, w, steps=1)
        return float(np.sum(w * e**2))

    q0, curvature = Q(r), (Q(r + h) - 2 * Q(r) + Q(r - h)) / h**2
    dof = max(3.0 * float(w.sum()) - (len(knots) - 4), 1.0)
    if curvature <= 0:
        return float("inf")
    return float(np.sqrt((q0 / dof) / (0.5 * curvature)))
