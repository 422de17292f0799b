"""Pass 1: every frame pair's camera rotation, the frames streamed at the flow's size.

Frames are decoded at about 480 px (:func:`flow.working_size`), the flow between
consecutive frames is computed ``ESTIMATE_CHUNK`` fields at a time, and the Hough
estimator (:mod:`rotation`) turns each field into R_t. With ``bands``, each pair's
rotation is also estimated from horizontal bands of the frame alone, which dates the
rows of a rolling-shutter frame (:attr:`VisualTrack.bands`). The similarity each
rotation leaves in the frame (the parallax of a walk) is measured on the background's
vectors, those that land within a few pixels of where the rotation puts them
(:mod:`stabilize.motion.residual`), refined first by Lucas–Kanade at the working size
(:func:`flow.refine.refine_at`): DIS's own error, shared by neighbouring vectors, was
all that measure read on a scene the rotation explains. At a high frame rate the flow
between frames a thirtieth of a second apart is sampled too, and kept
(:mod:`stabilize.motion.strides`).

Only the vectors measured where the first frame has texture in two directions
(:mod:`flow.texture`) vote for the frame's rotation and measure what it leaves: on a
flat wall, a sky or along an edge the flow is filled in, not measured (phone-cc9's
rotations against its gyro: 0.057° AAE, 0.090° with every vector). The bands keep every
finite vector, as does the focal length's search (:mod:`stabilize.motion.focal`): a band
holds a twelfth of the grid, which the texture would thin too far (gated, cockatoo's
readout read 5.4–11.5 ms instead of 2.9), and the search, given only textured vectors,
pinned phone-cc9 at 779 px (its calibration: 574).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

import flow
from flow.base import to_grey
from flow.refine import refine_at
from flow.resize import WorkingSize
from flow.texture import textured
from rotation import HoughEstimator
from rotation.camera import scale_intrinsics
from rotation.sampling import SampleGrid
from stabilize.motion.cuts import ALIKE, RESUME, likeness, resumes_from, thumbnail
from stabilize.motion.residual import gate_px, residual_motion
from stabilize.motion.track import Samples, VisualTrack, mean_rows
from stabilize.progress import Progress, no_progress
from stabilize.settings import Settings
from stabilize.video import VideoError, VideoInfo, frame_times, read_frames
from stabilize.video.fields import field_times
from stabilize.warp.lens import Lens, pinhole_map

ESTIMATE_CHUNK = 32  # flow fields held at once in pass 1
# Horizontal bands whose rotations date the rows (the readout). 12 rather than 6: on the
# rendered 15/25/33 ms clips the visual readout came within 0.4/1.5/1.9 ms instead of
# 0.3/1.8/2.1, and on phone-cc9 within 1.4 ms of the gyro's instead of 3.3.
READOUT_BANDS = 12


def estimate_rotations(
    path: str | Path,
    info: VideoInfo,
    settings: Settings,
    progress: Progress = no_progress,
    times: NDArray | None = None,
    *,
    bands: int = 0,
    lens: Lens | None = None,
    keep_samples: bool = False,
    settle: Settle | None = None,
    every: int = 1,
) -> VisualTrack:
    """Pass 1: the clip's rotations, frames streamed at the working size; with
    ``keep_samples``, the track keeps the flow vectors they came from (``samples``).
    With ``settle``, the estimator may change once, mid-stream (:class:`Settle`); until
    it has, the bands wait, and the samples are kept.

    Frame times are the container's timestamps unless given (e.g. from a sensor log).
    ``bands`` > 0 also estimates each pair's rotation from that many horizontal bands of
    the frame alone (for the rolling-shutter readout; about 0.5 ms per band and pair).
    With a fisheye ``lens`` the frames are first remapped to a pinhole view. With
    ``every`` ≥ 2, the flow vectors between frames that many apart are kept too
    (:attr:`VisualTrack.strides`; :mod:`stabilize.motion.strides`).
    """
    times = frame_times(path, info.input_args) if times is None else np.asarray(times)
    if len(times) < 2:
        raise VideoError(f"{path}: has {len(times)} frame(s); nothing to stabilise")
    ws = flow.working_size(info.size)
    backend = flow.get(settings.flow, **settings.flow_options)
    estimator, frames = _estimator_and_frames(path, info, settings, ws, lens)
    voted = 0 if settle else bands  # the bands voted in the stream, so far
    gate = gate_px(times)  # what the rotation may leave on the background
    keeping = keep_samples or settle is not None
    found: list[list[tuple]] = [[] for _ in range(voted + 1)]  # whole frame, then bands
    kept: list[tuple] = []
    residual: list[NDArray] = []
    masks = band_masks(estimator, ws.size[0], voted)
    textures: deque[NDArray] = deque()  # each frame's measurable vectors, until its pair
    greys: deque[NDArray] = deque()  # each frame in grey, until its pair is refined
    likenesses: list[float] = []  # each pair's (cuts.likeness)
    resumed: list[int] = []  # ... and, where unlike, how far back its picture resumes
    pictures = _noting_likeness(frames, likenesses, resumed)
    noted = _noting_texture(pictures, estimator.grid, textures, greys)
    strides: list[tuple] = []  # each stride's (u, v, valid, measured, fine u, fine v)
    if every >= 2:
        noted = _noting_strides(noted, every, backend, estimator, strides)
    # A chunk's vote runs while the next chunk's flow is computed: without the overlap,
    # pass 1 used 1.65 of this machine's 2 cores (1080p, 10 s, with the bands' votes
    # below: 7.8 s, 7.0 with it), when the flow kept one core busy; it now takes pairs
    # two at a time (flow.dis), and the vote fills the gaps its threads leave
    voting: Future | None = None
    with ThreadPoolExecutor(1) as voter:
        for u, v, valid in _sampled(estimator, backend.many(noted)):
            measured = valid & np.stack([textures.popleft() for _ in range(len(u))])
            fine = _refined(estimator.grid, greys, u, v, measured)
            if voting is not None:
                residual.append(_voted(voting, progress))
            if settle and len(found[0]) >= settle.after:  # asked once
                so_far = _so_far(times, found, residual, kept, estimator, ws)
                reached = len(found[0]) // every  # the strides the voted pairs span so far
                if every >= 2 and reached:  # for a high frame rate's search
                    measured_so_far = _samples(strides[:reached], estimator, ws)
                    so_far = replace(so_far, strides=measured_so_far, every=every)
                chosen = settle.choose(so_far)
                if chosen is not None:
                    estimator, voted, masks = chosen, bands, band_masks(chosen, ws.size[0], bands)
                    found, residual = _revoted(estimator, so_far.samples, masks, gate)
                    keeping = keep_samples
                    kept = kept if keeping else []
                settle = None
            voting = voter.submit(_vote, estimator, u, v, valid, measured, masks, found, fine, gate)
            if keeping:
                kept.append((u.astype(np.float32), v.astype(np.float32), valid, measured, *fine))
        if voting is not None:
            residual.append(_voted(voting, progress))
    n = len(found[0]) + 1
    if n < 2:
        raise VideoError(f"{path}: fewer than two frames decoded; nothing to stabilise")
    if n < len(times) - 1:
        raise Damaged(path, len(times), n)
    if len(times) != n:  # a frame's worth of slack for containers that list one extra
        times = times[:n] if len(times) > n else np.arange(n) / max(info.fps, 1.0)
    samples = _samples(kept, estimator, ws) if kept else None
    track = _track(times, found, voted)
    spanned = (n - 1) // every if every >= 2 else 0  # a frame lost at the end: one less
    return replace(
        track,
        samples=samples,
        residual=np.concatenate(residual),
        likeness=np.array(likenesses[: n - 1]),
        resumes=np.array(resumed[: n - 1], np.int64),
        strides=_samples(strides[:spanned], estimator, ws) if spanned else None,
        every=every if spanned else 1,
    )


class Damaged(VideoError):
    """A clip of which fewer frames decode than its container lists (``listed``,
    ``decoded``): damaged (a failing card, a broken stream), or truncated."""

    def __init__(self, path: str | Path, listed: int, decoded: int) -> None:
        super().__init__(
            f"{path}: truncated or damaged: the container lists {listed} frames, "
            f"only {decoded} decode"
        )
        self.path, self.listed, self.decoded = path, listed, decoded

    def frames_that_decode(self, info: VideoInfo) -> NDArray:
        """The times of the frames that do decode (each field's, where each is a
        frame), to run pass 1 again with, from the first frame the container lists
        (frames lost at the start leave the first at its own time); this error again
        where they are not the frames pass 1 read."""
        times = frame_times(self.path, info.input_args, decoded=True)
        times = field_times(times) if info.fields else times
        if abs(len(times) - self.decoded) > 1:  # (a container may list one extra)
            raise self
        return times

    @property
    def notice(self) -> str:
        return (
            f"damaged: {self.listed - self.decoded} of {self.listed} frames do not decode; "
            f"the {self.decoded} that do are used, each at its own time"
        )


@dataclass(frozen=True)
class Settle:
    """How pass 1 settles its estimator mid-stream (a focal length estimated from the
    clip's start): once ``after`` pairs are voted, ``choose`` is shown the track so far,
    samples kept, and returns the estimator to vote every pair with, bands and all (those
    so far again, from their samples), or None to keep the one it started with, bands
    left to the caller. It is asked once.

    Pairs voted after it settles are voted once, at its focal length, not at the
    starting one and again (1080p, 10 s: the focal estimate's share of pass 1 fell from
    11-12% to 6-7%)."""

    after: int
    choose: Callable[[VisualTrack], HoughEstimator | None]


def estimate_again(estimator: HoughEstimator, track: VisualTrack, bands: int = 0) -> VisualTrack:
    """A track's rotations estimated again from its kept samples by another
    ``estimator`` (of the same grid: another focal length), bands too, without decoding
    anything; what the pictures said (their likeness) is kept."""
    masks = band_masks(estimator, estimator.size[0], bands)
    found, residual = _revoted(estimator, track.samples, masks, gate_px(track.times))
    again = _track(track.times, found, bands)
    # the likeness once went missing here, so a clip whose focal length was estimated at
    # its end (any clip under MAX_PAIRS pairs) had no cut found
    return replace(
        again,
        samples=track.samples,
        residual=np.concatenate(residual),
        likeness=track.likeness,
        resumes=track.resumes,
        strides=track.strides,
        every=track.every,
    )


def _revoted(
    estimator: HoughEstimator, samples: Samples, masks: list[NDArray], gate: float
) -> tuple[list[list[tuple]], list[NDArray]]:
    """The found (R, support, mean row) lists and the similarities left (a chunk's
    array each, within ``gate`` px) of every pair of ``samples``, voted again by
    ``estimator``."""
    found: list[list[tuple]] = [[] for _ in range(len(masks) + 1)]
    residual = []
    fine_u, fine_v = samples.fine
    for part in _chunks(len(samples.u)):
        u, v, valid = samples.u[part], samples.v[part], samples.valid[part]
        fine = (fine_u[part], fine_v[part])
        voting = samples.voting[part]
        residual.append(_vote(estimator, u, v, valid, voting, masks, found, fine, gate))
    return found, residual


def _samples(kept: list[tuple], estimator: HoughEstimator, ws: WorkingSize) -> Samples:
    """The kept chunks' (u, v, valid, measured, fine u, fine v) as one :class:`Samples`."""
    grid = estimator.grid
    u, v, valid, measured, fine_u, fine_v = (
        np.concatenate(parts) for parts in zip(*kept, strict=True)
    )
    return Samples(
        u,
        v,
        valid,
        measured=measured,
        fine_u=fine_u,
        fine_v=fine_v,
        x=grid.x,
        y=grid.y,
        rows=_grid_pixels(grid)[1].astype(np.float64),
        height=ws.size[0],
        scale=ws.scale[0],
    )


def _so_far(
    times: NDArray,
    found: list[list[tuple]],
    residual: list[NDArray],
    kept: list[tuple],
    estimator: HoughEstimator,
    ws: WorkingSize,
) -> VisualTrack:
    """The whole-frame track of the pairs voted so far, with their samples."""
    n = len(found[0])
    track = _track(times[: n + 1], found[:1], 0)
    return replace(track, samples=_samples(kept, estimator, ws), residual=np.concatenate(residual))


def with_bands(estimator: HoughEstimator, track: VisualTrack, bands: int) -> VisualTrack:
    """The track with each pair's rotation also estimated from ``bands`` horizontal
    bands of its kept samples, by the ``estimator`` its rotations came from: pass 1
    leaves the bands to this when the focal length may still change, since a new one
    estimates them again anyway (1080p, 10 s: about 1 s of pass 1 saved when this came,
    before the bands were voted in one call a chunk)."""
    if not bands:
        return track
    samples = track.samples
    masks = band_masks(estimator, estimator.size[0], bands)
    found: list[list[tuple]] = [[] for _ in masks]
    for part in _chunks(len(samples.u)):
        u, v, valid = samples.u[part], samples.v[part], samples.valid[part]
        _vote_sets(estimator, u, v, [valid & mask for mask in masks], found)
    R_b, rows_b, support_b = _stacked(found)
    return replace(track, bands=R_b, band_rows=rows_b, band_support=support_b)


def _chunks(n: int) -> Iterator[slice]:
    """``ESTIMATE_CHUNK`` pairs at a time, of n."""
    return (slice(first, first + ESTIMATE_CHUNK) for first in range(0, n, ESTIMATE_CHUNK))


def _track(times: NDArray, found: list[list[tuple]], bands: int) -> VisualTrack:
    R, support, rows = (np.array([item[i] for item in found[0]]) for i in range(3))
    if not bands:
        return VisualTrack(times, R, support, rows)
    R_b, rows_b, support_b = _stacked(found[1:])
    return VisualTrack(times, R, support, rows, R_b, rows_b, support_b)


def _stacked(found: list[list[tuple]]) -> tuple[NDArray, NDArray, NDArray]:
    """The bands' (R, mean row, support), each stacked (B, N-1, ...)."""
    return tuple(
        np.stack([np.array([item[i] for item in band]) for band in found]) for i in (0, 2, 1)
    )


def _estimator_and_frames(
    path: str | Path, info: VideoInfo, settings: Settings, ws: WorkingSize, lens: Lens | None
) -> tuple[HoughEstimator, Iterator[NDArray]]:
    """The estimator at the working size, and the frames it sees: the decoded frames, or
    through a fisheye ``lens``, their pinhole view."""
    frames = read_frames(path, ws.size, info)
    if lens is None:
        focal = settings.focal_px(info.size) * ws.scale[0]
        return HoughEstimator(ws.size, focal, max_deg=settings.max_deg), frames
    estimator = lens_estimator(lens, ws, settings.max_deg)
    K_ws = scale_intrinsics(lens.K, *ws.scale)
    maps = pinhole_map(replace(lens, K=K_ws), ws.size, estimator.focal, estimator.center)
    return estimator, (cv2.remap(f, *maps, cv2.INTER_LINEAR) for f in frames)


def lens_estimator(lens: Lens, ws: WorkingSize, max_deg: float) -> HoughEstimator:
    """The estimator of a fisheye ``lens``'s pinhole view at the working size: its focal
    length and principal point."""
    K_ws = scale_intrinsics(lens.K, *ws.scale)
    center = (float(K_ws[0, 2]), float(K_ws[1, 2]))
    return HoughEstimator(ws.size, float(K_ws[0, 0]), center=center, max_deg=max_deg)


def _noting_texture(
    frames: Iterator[NDArray], grid: SampleGrid, textures: deque[NDArray], greys: deque[NDArray]
) -> Iterator[NDArray]:
    """The frames as they are, noting in ``textures`` where each has the texture to
    measure flow at the sample grid (:func:`flow.texture.textured`), and in ``greys``
    the frame in grey, for its pairs' vectors to be refined (:func:`_refined`)."""
    for frame in frames:
        grey = to_grey(frame)  # once: the texture's and the refinement's
        textures.append(textured(grey, grid.rows, grid.cols))
        greys.append(grey)
        yield frame


def _refined(
    grid: SampleGrid, greys: deque[NDArray], u: NDArray, v: NDArray, measured: NDArray
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """The vectors u, v (n, M) of the n pairs that the first n + 1 of ``greys`` make,
    refined by Lucas–Kanade at the grid's points where ``measured`` (n, M)
    (:func:`flow.refine.refine_at`), the others as they are: only those measure what a
    rotation leaves. The first n greys are dropped, their pairs done."""
    x, y = _grid_pixels(grid)
    fine_u, fine_v = u.astype(np.float32), v.astype(np.float32)
    for k, at in enumerate(measured):
        earlier = greys.popleft()
        fine_u[k, at], fine_v[k, at] = refine_at(
            earlier, greys[0], x[at], y[at], u[k, at], v[k, at]
        )
    return fine_u, fine_v


def _grid_pixels(grid: SampleGrid) -> tuple[NDArray, NDArray]:
    """The grid's points as (column, row) pixel positions (M,), in the samples' order."""
    return np.tile(grid.cols, len(grid.rows)), np.repeat(grid.rows, len(grid.cols))


def _noting_strides(
    frames: Iterator[NDArray],
    every: int,
    backend: flow.FlowBackend,
    estimator: HoughEstimator,
    strides: list[tuple],
) -> Iterator[NDArray]:
    """The frames as they are, the flow from each ``every``-th frame to the next such
    sampled into ``strides`` as it streams: (u, v, valid, measured, fine u, fine v) of
    one pair each, measured where the earlier frame has texture and refined there
    (:func:`_refined`; one field more per ``every`` pairs; only the last such frame is
    held)."""
    grid = estimator.grid
    key: NDArray | None = None
    for index, frame in enumerate(frames):
        if index % every == 0:
            if key is not None:
                u, v, valid = estimator.samples(backend(key, frame)[None])
                measured = valid & textured(key, grid.rows, grid.cols)
                kept = (u.astype(np.float32), v.astype(np.float32), valid, measured)
                strides.append((*kept, *_refined(grid, deque([key, frame]), u, v, measured)))
            key = frame
        yield frame


def _noting_likeness(
    frames: Iterator[NDArray], likenesses: list[float], resumed: list[int]
) -> Iterator[NDArray]:
    """The frames as they are, noting in ``likenesses`` how alike each looks to the one
    before (:func:`stabilize.motion.cuts.likeness`: about 0.2 ms a pair, with the
    thumbnails), and in ``resumed``, where they look unlike, how far back it finds a
    picture it looks alike to (:func:`stabilize.motion.cuts.resumes_from`; 0 elsewhere)."""
    recent: deque[NDArray] = deque(maxlen=RESUME + 1)
    for frame in frames:
        small = thumbnail(frame)
        if recent:
            alike = likeness(recent[-1], small)
            likenesses.append(alike)
            resumed.append(resumes_from(recent, small) if alike < ALIKE else 0)
        recent.append(small)
        yield frame


def band_masks(estimator: HoughEstimator, height: int, bands: int) -> list[NDArray]:
    """Which sample vectors vote for each of ``bands`` horizontal bands (those whose
    row lies in it); every vector votes for the whole frame."""
    rows = _grid_pixels(estimator.grid)[1]
    edges = np.linspace(0, height, bands + 1).round().astype(int)
    return [(rows >= edges[b - 1]) & (rows < edges[b]) for b in range(1, bands + 1)]


def _voted(voting: Future, progress: Progress) -> NDArray:
    """A chunk's similarities once its vote (:func:`_vote`) is done, its pairs counted
    as progress."""
    residual = voting.result()
    progress(len(residual))
    return residual


def _sampled(estimator: HoughEstimator, flows: Iterator[NDArray]) -> Iterator[tuple]:
    """(u, v, valid) of ``ESTIMATE_CHUNK`` flow fields at a time."""
    chunk: list[NDArray] = []
    for f in flows:
        chunk.append(f)
        if len(chunk) == ESTIMATE_CHUNK:
            yield estimator.samples(np.stack(chunk))
            chunk.clear()
    if chunk:
        yield estimator.samples(np.stack(chunk))


def _vote(
    estimator: HoughEstimator,
    u: NDArray,
    v: NDArray,
    valid: NDArray,
    measured: NDArray,
    masks: list[NDArray],
    found: list[list[tuple]],
    fine: tuple[NDArray, NDArray],
    gate: float,
) -> NDArray:
    """(R, support, mean row) of each pair into ``found``: the whole frame from the
    ``measured`` vectors, then each band (its mask in ``masks``) from its ``valid``
    ones; returns the similarity (n, 4) each whole-frame rotation leaves on the measured
    vectors, refined (``fine``: their u, v), within ``gate`` px of it."""
    grid = estimator.grid
    votes = [measured, *(valid & mask for mask in masks)]
    R = np.array([est.matrix for est in _vote_sets(estimator, u, v, votes, found)[0]])
    return residual_motion(grid.x, grid.y, *fine, measured, R, estimator.focal, gate)


def _vote_sets(
    estimator: HoughEstimator, u: NDArray, v: NDArray, votes: list[NDArray], found: list
) -> list[list]:
    """The n pairs' rotations (u, v (n, M)) from each of ``votes``' sets of vectors
    (n, M), their (R, support, mean row) into the matching list of ``found``; returns
    the estimates, a list per set. One call for every set: a call per band and chunk
    spent much of the bands' time starting threads and waiting on the slowest
    (with_bands on 1080p, 10 s: 0.37–0.42 s so, 0.22–0.28 s with this and the mean rows
    stacked)."""
    n = len(u)
    times = len(votes)
    stacked = estimator.estimate_samples(
        np.tile(u, (times, 1)), np.tile(v, (times, 1)), np.concatenate(votes)
    )
    estimates = [stacked[k * n : (k + 1) * n] for k in range(times)]
    for into, part in zip(found, estimates, strict=True):
        _note(estimator, part, into)
    return estimates


def _note(estimator: HoughEstimator, estimates: list, into: list[tuple]) -> None:
    """Each estimate's (R, support, mean row) appended to ``into``."""
    if not estimates:
        return
    inliers = np.stack([est.inliers for est in estimates])
    rows = mean_rows(inliers, estimator.grid.rows, estimator.size[0])
    into.extend((est.matrix, est.support, row) for est, row in zip(estimates, rows, strict=True))
