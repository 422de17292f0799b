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
corrected. A sensor's readout is one figure, so one that the clip's two halves read
apart (:func:`halves_disagree`) is refused too: the fit followed something else.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from stabilize.gyro.sync import MIN_READOUT, SIGNIFICANT, golden_section
from stabilize.motion.track import VisualTrack
from stabilize.shutter.attitude import Bands, Spline, fit_attitude, knots_for
from stabilize.video.decode import frame_interval

GRID = 29  # readouts tried across -0.2..1.2 frame intervals
MAX_SEARCH_PAIRS = 900  # pairs the readout is searched on (30 s at 30 fps)
MIN_PAIRS = 20  # pairs with three usable bands, fewest that date the rows
MAX_STDERR = 0.06  # of a frame interval (2 ms at 30 fps): a less certain readout is refused
LONGEST, SHORTEST = 1.05, -0.1  # frame intervals: readouts outside these are impossible
# The halves of the searched pairs must agree (halves_disagree). Measured, the halves'
# readouts (ms) and how many σ apart: phone-cc9 24.7 and 32.3, 2.4 σ (its gyro: 25.4),
# zoomed in to 31° 12.3 and 11.6; karma at 640 px 23.4 and 34.5, 5.2 σ; cockatoo at
# 640 px 12.8 and 4.5, 4.7 σ (at full size it now reads -9.2 ± 0.9, refused as negative,
# where it once read 3.1); karma's middle half and third 6.7 and 26.2, 8.7 and 21.9.
SPLIT_SIGMAS = 3.0
SPLIT_RATIO = 2.0


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


def readout_for(
    option: float | str, track: VisualTrack, repaired: NDArray | None = None
) -> tuple[Readout, Spline | None]:
    """The readout ``--rolling-shutter`` asks for ('auto', 'off' or ms), and the attitude
    fitted at it (None where nothing is corrected). The pairs ``repaired`` (their turns
    taken from their neighbours', :mod:`stabilize.motion.repair`) date nothing, and the
    attitude is not fitted to them: a black frame dropped into 6 s of karma's flight,
    its two pairs' bands kept, read 2.3 ms where the clip reads 21.0, and the attitude
    then turned by the black frame's 0.73°, which the repair had taken out."""
    if option == "off":
        return Readout(0.0, "off"), None
    if repaired is not None and track.band_support is not None:
        track = _without(track, np.asarray(repaired, bool))
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
    minute), and the attitude is then fitted to the whole clip once. A readout found is
    searched again on each half of those pairs, and refused where they disagree
    (:func:`halves_disagree`).

    At a high frame rate it is searched on the strides a thirtieth of a second long
    (:attr:`VisualTrack.stride_track`), and certain enough as a 30 fps pair's would be:
    the pairs of a 240 fps clip turn too little for their bands to tell the rows' times
    apart, and a rendered global shutter read 1.8 ± 0.1 ms on them (the same walk with a
    3 ms readout 2.1 ± 0.1), on strides 0.9 ± 0.4 (3.9 ± 0.4). A clip of fewer than
    ``MIN_PAIRS`` strides (under 0.7 s) is searched on its pairs, as before."""
    frame = frame_interval(track.times)
    dated = track.stride_track if _dates_rows(track.stride_track) else track
    first = _most_shaking(dated, MAX_SEARCH_PAIRS)
    searched = dated.pairs(first, first + MAX_SEARCH_PAIRS) if first is not None else dated
    found = _search(searched, frame)
    if found is None:
        reason = "too few frames with texture across their height"
        return Readout(0.0, "refused", reason=reason), None
    r, stderr, bands, knots, scale = found
    readout = decide(r, stderr, frame, frame_interval(dated.times))
    if not readout.seconds:
        return readout, None
    half = len(searched.rotations) // 2
    halves = [_search(searched.pairs(a, b), frame) for a, b in ((0, half), (half, 2 * half))]
    # a half that reads an impossible readout measured none, and contradicts nothing
    if all(h is not None and _possible(h[0], frame) for h in halves):
        (r1, s1, *_), (r2, s2, *_) = halves
        if halves_disagree(r1, s1, r2, s2):
            reason = (
                f"the clip's halves disagree ({1000 * r1:.1f} ± {1000 * s1:.1f} and "
                f"{1000 * r2:.1f} ± {1000 * s2:.1f} ms): not the sensor's"
            )
            return Readout(0.0, "refused", r, stderr, reason), None
    if first is not None or dated is not track:  # the attitude of the whole clip
        bands, knots = Bands.of(track), knots_for(track.times)
        scale = cauchy_scale(bands, r, knots)
    spline, _, _ = fit_attitude(bands, r, knots, scale)
    return readout, spline


def _search(track: VisualTrack, frame: float) -> tuple[float, float, Bands, NDArray, float] | None:
    """(r, σ_r, and the bands, knots and Cauchy scale it was searched with) over a
    track's pairs; None where too few of them have three usable bands."""
    bands = Bands.of(track)
    per_pair = bands.usable.reshape(len(track.bands), -1).sum(0)
    if int((per_pair >= 3).sum()) < MIN_PAIRS:
        return None
    knots = knots_for(track.times)
    scale = cauchy_scale(bands, 0.5 * frame, knots)

    def cost(r: float) -> float:
        _, e, _ = fit_attitude(bands, r, knots, scale)
        return float(np.sum(bands.usable * np.log1p((e / scale) ** 2)))

    grid = np.linspace(-0.2 * frame, 1.2 * frame, GRID)
    best = int(np.argmin([cost(r) for r in grid]))
    step = grid[1] - grid[0]
    r = golden_section(cost, grid[max(best - 1, 0)], grid[min(best + 1, GRID - 1)], 1e-2 * step)
    stderr = curvature_stderr(bands, r, knots, scale, 0.05 * frame)
    return r, stderr, bands, knots, scale


def _has_bands(track: VisualTrack | None) -> bool:
    """Whether there is a track, with band rotations."""
    return track is not None and track.bands is not None


def _dates_rows(strided: VisualTrack | None) -> bool:
    """Whether a clip's strides can date its rows: they have bands, and enough pairs."""
    return _has_bands(strided) and len(strided.rotations) >= MIN_PAIRS


def _without(track: VisualTrack, repaired: NDArray[np.bool_]) -> VisualTrack:
    """The track with the bands of the ``repaired`` pairs, and of its strides that span
    one, given no support: they date nothing."""
    unusable = np.where(repaired[None], 0.0, track.band_support)
    strided = track.stride_track
    if _has_bands(strided):
        count = len(strided.rotations)
        spans = repaired[: count * track.every].reshape(count, track.every).any(axis=1)
        support = np.where(spans[None], 0.0, strided.band_support)
        strided = replace(strided, band_support=support)
    return replace(track, band_support=unusable, stride_track=strided)


def _possible(r: float, frame: float) -> bool:
    """Whether a readout r (s) is one a sensor of that frame interval can have."""
    return SHORTEST * frame < r < LONGEST * frame


def halves_disagree(r1: float, s1: float, r2: float, s2: float) -> bool:
    """Whether two halves' readouts (s, with σ) differ by more than ``SPLIT_SIGMAS`` σ
    and by more than a factor of ``SPLIT_RATIO``: a sensor's readout is one figure, so a
    fit whose halves read such different ones follows something else (a subject, a
    drone's vibration). Either alone is not enough: σ, from the fit's curvature, is
    optimistic (rendered errors of 0.4–1.9 ms against 0.1), and small readouts differ by
    large factors within their noise."""
    apart = abs(r1 - r2) > SPLIT_SIGMAS * np.hypot(s1, s2)
    return bool(apart and min(r1, r2) < max(r1, r2) / SPLIT_RATIO)


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


def decide(r: float, stderr: float, frame: float, span: float | None = None) -> Readout:
    """Refuse an uncertain or impossible readout r (s, with σ ``stderr``, at a frame
    interval ``frame``, measured on pairs ``span`` s apart: ``frame`` unless said), call
    a negligible one 0; the attitude is fitted only to one kept."""
    if not stderr <= MAX_STDERR * (frame if span is None else span):
        return Readout(0.0, "refused", r, stderr, "the motion does not pin it down")
    if r >= LONGEST * frame:
        return Readout(0.0, "refused", r, stderr, "longer than a frame interval")
    if r <= SHORTEST * frame:
        reason = "negative: a bottom-to-top readout is not modelled"
        return Readout(0.0, "refused", r, stderr, reason)
    if r < max(SIGNIFICANT * stderr, MIN_READOUT):
        return Readout(0.0, "estimated", r, stderr, "no rolling shutter measured")
    return Readout(r, "estimated", r, stderr)


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
