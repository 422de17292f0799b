"""The camera's focal length: given, from a lens profile, from the file's metadata, or
estimated from the clip's own flow (:mod:`rotation.focal`), in that order of trust.

A wrong focal length is not harmless: rotational flow carries x²/f and xy/f terms at the
frame's edges, so a wrong f leaves keystone wobble there and mixes the axes. With no
``--fov``, ``--focal`` or ``--lens`` (``--fov auto``), pass 1 starts at the metadata's
focal length (or the 69° default). Once it has voted the clip's first ``MAX_PAIRS`` pairs,
the focal length is estimated from the flow vectors they kept; those pairs are voted again
at it, and the rest of the clip only at it, without decoding anything twice. Where the
clip's start does not pin f down, the estimate is made at the end, on the clip's most
turning ``MAX_PAIRS`` pairs, and every pair is voted again. An estimate within 15% of the
metadata's keeps the metadata's (the finer figure); a clip that does not pin f down (a
tripod, pure roll, too little motion) keeps the starting value, and says so, unless the
search's curve rules that value out (:meth:`rotation.focal.FocalEstimate.rules_out`: a
narrow lens's curve lies flat over the long focal lengths, and reads the 69° default far
up its steep wide side); then the nearest focal length the curve accepts is taken. At 45
fps and more the estimate is made on the clip's strides (:mod:`stabilize.motion.strides`),
its first ``MAX_PAIRS`` of them (at the end where it has fewer), and every pair is then
held to them.

An edited clip (:mod:`stabilize.motion.cuts`) may join shots of two cameras. Each shot of
at least ``MIN_SHOT_PAIRS`` pairs whose own motion pins a focal length down ``SHOT_APART``
or more from the clip's is voted again at it, and warped through it (``FocalChoice.shots``):
a rendered 40° street cut to a 100° one was estimated at 40.6° whole, and its 100° shot,
stabilised at that, kept 0.91 px of residual shake; at its own 98.4°, 0.65 (0.62 alone).

Phones write a 35 mm-equivalent focal length F (QuickTime's
``com.apple.quicktime.camera.focal_length.35mm_equivalent``, EXIF's
``FocalLengthIn35mmFilm``), defined on the 43.27 mm diagonal of a 36×24 mm frame:

    f_px = F · √(W² + H²) / 43.27.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

import flow
from rotation import HoughEstimator, so3
from rotation.camera import focal_from_fov, fov_from_focal
from rotation.focal import FocalEstimate, estimate_focal
from stabilize.motion.cuts import shots, track_breaks
from stabilize.motion.estimate import (
    Settle,
    estimate_again,
    estimate_rotations,
    lens_estimator,
    with_bands,
)
from stabilize.motion.strides import held_to_strides, stride_for, strided_track, within
from stabilize.motion.track import VisualTrack
from stabilize.progress import Progress, no_progress
from stabilize.settings import Settings
from stabilize.video import VideoInfo
from stabilize.video.sequence import first_image, picture
from stabilize.warp.lens import Lens

FULL_FRAME_DIAGONAL_MM = 43.27
FOV_BOUNDS = (15.0, 150.0)  # the fields of view searched, degrees across the long side
MAX_PAIRS = 120  # consecutive pairs the estimate is made on (the most-turning stretch)
MIN_TURN_DEG = 0.05  # median pitch/yaw per pair below which f is not pinned down
DISAGREES = 0.15  # an estimate this far from the metadata's is reported
# An edited clip's shot whose own estimate lies this far from the clip's is voted and
# warped at its own (:func:`_by_shot`), where it has at least MIN_SHOT_PAIRS pairs
SHOT_APART = 0.15
MIN_SHOT_PAIRS = 30

_METADATA = re.compile(
    r"(?:focal_length\.35mm_equivalent|FocalLengthIn35mmFilm|focal_length_35mm)\s*:\s*([\d.]+)"
)


@dataclass(frozen=True)
class FocalChoice:
    """The focal length used, in pixels at the video's size, and where it came from:
    ``given``, ``lens``, ``metadata``, ``estimated`` or ``default``."""

    px: float
    span: int  # px the field of view spans: the frame's long side
    source: str
    estimated_px: float | None = None
    metadata_px: float | None = None
    note: str = ""
    # an edited clip's shots whose own motion pins another focal length down (a montage
    # of two cameras): (first frame, stop, px) each; the other frames have ``px``
    shots: tuple[tuple[int, int, float], ...] = ()

    @property
    def fov_deg(self) -> float:
        return fov_from_focal(self.px, self.span)

    def said_shots(self, times: NDArray) -> str:
        """The shots of their own focal length as a notice says them, their first
        frames at ``times`` (s); "" where none.

        >>> choice = FocalChoice(500.0, 640, "estimated", shots=((90, 180, 268.5),))
        >>> choice.said_shots(np.arange(180) / 30)
        'shots of another camera, each at its own: 100.0° from 3.00 s'
        """
        if not self.shots:
            return ""
        said = ", ".join(
            f"{fov_from_focal(px, self.span):.1f}° from {times[first]:.2f} s"
            for first, _, px in self.shots
        )
        return f"shots of another camera, each at its own: {said}"

    def per_frame(self, frames: int) -> NDArray[np.float64]:
        """The focal length (px) of each of ``frames`` frames: its shot's own, else the
        clip's."""
        px = np.full(frames, self.px)
        for first, stop, own in self.shots:
            px[first:stop] = own
        return px

    def summary(self) -> dict:
        return {
            "px": self.px,
            "fov_deg": self.fov_deg,
            "source": self.source,
            "estimated_px": self.estimated_px,
            "metadata_px": self.metadata_px,
            "note": self.note,
            "shots": [
                {"first_frame": first, "px": own, "fov_deg": fov_from_focal(own, self.span)}
                for first, _, own in self.shots
            ],
        }


def metadata_focal(info: VideoInfo) -> float | None:
    """The focal length (px) the file's metadata gives as a 35 mm equivalent, if any:
    a video's QuickTime keys, or the EXIF of an image sequence's first image."""
    h, w = info.size
    equivalent = _tag_35mm(info.metadata) if info.metadata else None
    if equivalent is None and info.input_args:
        equivalent = _exif_35mm(info)
    if not equivalent:
        return None
    return equivalent * math.hypot(w, h) / FULL_FRAME_DIAGONAL_MM


def _tag_35mm(text: str) -> float | None:
    found = _METADATA.search(text)
    return float(found.group(1)) if found else None


def _exif_35mm(info: VideoInfo) -> float | None:
    """FocalLengthIn35mmFilm (tag 41989) of the first image of a %d pattern."""
    number = first_image(info.input_args)
    first = picture(info.path, 1 if number is None else number)
    try:
        from PIL import Image

        with Image.open(first) as image:
            value = image.getexif().get_ifd(0x8769).get(41989)
    except (OSError, ValueError, ImportError):
        return None
    return float(value) if value else None


def initial_focal(settings: Settings, info: VideoInfo, lens: Lens | None) -> FocalChoice:
    """The focal length pass 1 starts from: given, the lens's, the metadata's, or the
    default; the last two are where the estimate starts (:func:`estimate_motion`)."""
    span = max(info.size)  # as --fov's, however the camera was held
    meta = metadata_focal(info)
    if settings.fov_given:
        return FocalChoice(settings.focal_px(info.size), span, "given", metadata_px=meta)
    if lens is not None:
        return FocalChoice(float(lens.K[0, 0]), span, "lens", metadata_px=meta)
    if meta is not None:
        return FocalChoice(meta, span, "metadata", metadata_px=meta)
    return FocalChoice(settings.focal_px(info.size), span, "default")


def estimate_motion(
    path: str | Path,
    info: VideoInfo,
    settings: Settings,
    progress: Progress = no_progress,
    times: NDArray | None = None,
    *,
    bands: int = 0,
    lens: Lens | None = None,
    keep_samples: bool = False,
) -> tuple[VisualTrack, FocalChoice]:
    """Pass 1 with the focal length resolved: the track, and the focal length it was
    estimated at (:class:`FocalChoice`); with ``keep_samples``, the track keeps its flow
    vectors (they are kept while the focal length is estimated, and dropped after).
    The estimate is tried once pass 1 has voted ``MAX_PAIRS`` pairs (a whole number of
    chunks: 128), and again at the end where those do not pin it down."""
    choice = initial_focal(settings, info, lens)
    auto = choice.source in ("metadata", "default")  # nothing given: estimated
    every = stride_for(info.fps)
    ws = flow.working_size(info.size)
    start = (
        HoughEstimator(ws.size, choice.px * ws.scale[0], max_deg=settings.max_deg)
        if lens is None
        else lens_estimator(lens, ws, settings.max_deg)
    )
    long_side = choice.span * ws.scale[0]  # as the default's 69°, however it is held
    settled: list[FocalChoice] = []

    def voting_at(focal: float) -> HoughEstimator:  # px at the flow's size
        return HoughEstimator(ws.size, focal, max_deg=settings.max_deg)

    def estimator(resolved: FocalChoice) -> HoughEstimator:
        if resolved.source != "estimated":
            return start
        return voting_at(resolved.px * ws.scale[0])

    def settle(so_far: VisualTrack) -> HoughEstimator | None:
        found = focal_from_track(strided_track(so_far, start) or so_far, start, long_side).focal
        if found is None:
            return None
        settled.append(_resolved(choice, found / ws.scale[0]))
        return estimator(settled[0])

    def strided(track: VisualTrack, resolved: FocalChoice) -> VisualTrack:
        voted = _strides_voted(track, resolved, estimator, voting_at, bands)
        return held_to_strides(track, voted)

    # at a high frame rate the focal length is searched on the strides, once MAX_PAIRS
    # of them are measured (4 s at 240 fps), or at the end: a pair of a 240 fps clip
    # turns too little to tell its x²/f terms from the flow's noise (a rendered 240 fps
    # walk read f 43% long on its pairs, within 1% on strides)
    track = estimate_rotations(
        path,
        info,
        replace(settings, focal=choice.px, fov=None),
        progress,
        times,
        bands=bands,
        lens=lens,
        keep_samples=keep_samples,
        settle=Settle(MAX_PAIRS * every, settle) if auto else None,
        every=every,
    )
    if not auto:
        return strided(track, choice), choice
    if settled:  # its samples dropped after the settling, unless asked for
        track, resolved = _by_shot(
            track, settled[0], estimator(settled[0]), voting_at, long_side, bands
        )
        return strided(track, resolved), resolved
    kept = (lambda t: t) if keep_samples else (lambda t: replace(t, samples=None))
    curve = focal_from_track(strided_track(track, start) or track, start, long_side)
    if curve.focal is not None:
        resolved = _resolved(choice, curve.focal / ws.scale[0])
    elif curve.rules_out(start.focal):  # pins none, but not this one either
        resolved = _ruled_out(choice, curve.nearest_accepted(start.focal) / ws.scale[0])
    else:
        note = _kept_note(choice)
        resolved = replace(choice, note=note)
    voted = estimator(resolved)  # start's, unless estimated
    if resolved.source != "estimated":
        track = with_bands(voted, track, bands)
    else:
        track = estimate_again(voted, track, bands)
    track, resolved = _by_shot(track, resolved, voted, voting_at, long_side, bands)
    return kept(strided(track, resolved)), resolved


def _strides_voted(
    track: VisualTrack,
    resolved: FocalChoice,
    estimator: Callable[[FocalChoice], HoughEstimator],
    voting_at: Callable[[float], HoughEstimator],
    bands: int = 0,
) -> VisualTrack | None:
    """The track's strides (:mod:`stabilize.motion.strides`) voted at the focal length
    ``resolved``, those within a shot of its own at that shot's, with ``bands`` bands
    each; None where it has none."""
    voted = estimator(resolved)
    strided = strided_track(track, voted, bands)
    if strided is None:
        return None
    scale = voted.focal / resolved.px  # flow px per input px
    for first, stop, px in resolved.shots:  # frames first..stop-1
        j0, j1 = within(first, stop, track.every)
        if j1 > j0:
            part = estimate_again(voting_at(px * scale), strided.pairs(j0, j1), bands)
            strided = strided.spliced(j0, part)
    return strided


def _by_shot(
    track: VisualTrack,
    resolved: FocalChoice,
    voted: HoughEstimator,
    voting_at: Callable[[float], HoughEstimator],
    long_side: float,
    bands: int,
) -> tuple[VisualTrack, FocalChoice]:
    """An edited clip's shots each at its own focal length, where its motion pins one
    down ``SHOT_APART`` or more from the clip's (a montage of two cameras), its pairs
    voted again at it (by ``voting_at`` that focal length, px at the flow's size); the
    track was ``voted`` at the clip's. A shot of fewer than ``MIN_SHOT_PAIRS`` pairs
    keeps the clip's. At a high frame rate a shot is searched on its strides, as the
    clip is (a rendered 240 fps montage's 40° and 100° shots pinned nothing down on their
    pairs, and read -1.5% and +4% on their strides), and needs as many of them."""
    cuts = track_breaks(track).cuts
    if track.samples is None or not cuts.any():
        return track, resolved
    scale = voted.focal / resolved.px  # flow px per input px
    strided = strided_track(track, voted)
    own: list[tuple[int, int, float]] = []
    for first, stop in shots(cuts):
        part = track.pairs(first, stop - 1)
        searched = part if strided is None else strided.pairs(*within(first, stop, track.every))
        if len(searched.rotations) < MIN_SHOT_PAIRS:
            continue
        found = focal_from_track(searched, voted, long_side).focal
        if found is None or abs(found / voted.focal - 1) < SHOT_APART:
            continue
        track = track.spliced(first, estimate_again(voting_at(found), part, bands))
        own.append((first, stop, found / scale))
    return track, replace(resolved, shots=tuple(own))


def _kept_note(start: FocalChoice) -> str:
    """The note where the clip's motion pins no focal length down and ``start``'s is
    kept: which, and the option that gives the lens's own, since a wrong one leaves
    keystone wobble at the frame's edges (up to 3× the residual shake on real clips)."""
    kept = f"the {start.source}'s {start.fov_deg:.1f}°"
    if start.source == "default":
        kept += " (a phone's main camera)"
    return (
        f"the clip's motion does not pin the focal length down: {kept} kept; "
        "--fov gives the lens's own"
    )


def _ruled_out(start: FocalChoice, px: float) -> FocalChoice:
    """The focal length ``px`` (the input's px) nearest ``start``'s that a curve which
    pins none down accepts, where it rules ``start``'s out: taken even near the
    metadata's, since the curve reads the metadata's clearly worse."""
    note = (
        f"the clip's motion pins no focal length down, but rules out the {start.source}'s "
        f"{start.fov_deg:.1f}°: the nearest it accepts, {fov_from_focal(px, start.span):.1f}°, "
        "is taken"
    )
    meta = start.metadata_px
    off = _off_metadata(px, meta)
    return FocalChoice(px, start.span, "estimated", px, meta, f"{note} ({off})" if off else note)


def _resolved(start: FocalChoice, px: float) -> FocalChoice:
    """The focal length kept once the clip's estimate is ``px`` (the input's px): the
    metadata's where the two agree (the lens's own figure is the finer), else the
    estimate, noted where it disagrees with the metadata."""
    meta = start.metadata_px
    if meta and abs(px / meta - 1) <= DISAGREES:
        return replace(start, estimated_px=px)
    off = _off_metadata(px, meta)
    return FocalChoice(
        px, start.span, "estimated", px, meta, f"{off} (a digital zoom?)" if off else ""
    )


def _off_metadata(px: float, meta: float | None) -> str:
    """How far ``px`` lies from the metadata's focal length, if any ("" if none)."""
    return f"{100 * (px / meta - 1):+.0f}% off the metadata's" if meta else ""


def focal_from_track(
    track: VisualTrack, estimator: HoughEstimator, long_side: float
) -> FocalEstimate:
    """The focal length (px at the flow's size) from a track's kept samples, estimated at
    ``estimator``'s focal length, searched over ``FOV_BOUNDS`` across the frame's
    ``long_side`` (px at the flow's size), with its cost curve; no focal length where
    the motion does not pin it down, and no curve either where it turns too little."""
    samples = track.samples
    rotvecs = so3.log_so3(track.rotations)
    turn = np.degrees(np.hypot(rotvecs[:, 0], rotvecs[:, 1]))
    if samples is None or len(turn) < 3 or np.median(turn) < MIN_TURN_DEG:
        return FocalEstimate(None, np.zeros(0), np.zeros(0), 0)
    first = _most_turning(turn, MAX_PAIRS)
    part = slice(first, first + MAX_PAIRS)
    bounds = tuple(focal_from_fov(fov, long_side) for fov in FOV_BOUNDS[::-1])
    grid = estimator.grid
    return estimate_focal(
        grid.x,
        grid.y,
        samples.u[part],
        samples.v[part],
        samples.valid[part],
        rotvecs[part],
        estimator.focal,
        bounds,
    )


def _most_turning(turn: NDArray, n: int) -> int:
    """The first pair of the n consecutive pairs that turn the most, in pitch and yaw."""
    if len(turn) <= n:
        return 0
    window = np.convolve(turn, np.ones(n), mode="valid")
    return int(np.argmax(window))
