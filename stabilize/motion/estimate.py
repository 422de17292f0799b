"""Pass 1: every frame pair's camera rotation, the frames streamed at the flow's size.

Frames are decoded at about 480 px (:func:`flow.working_size`), the flow between
consecutive frames is computed ``ESTIMATE_CHUNK`` fields at a time, and the Hough
estimator (:mod:`rotation`) turns each field into R_t. With ``bands``, each pair's
rotation is also estimated from horizontal bands of the frame alone, which dates the
rows of a rolling-shutter frame (:attr:`VisualTrack.bands`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

import flow
from flow.resize import WorkingSize
from rotation import HoughEstimator
from rotation.camera import scale_intrinsics
from stabilize.motion.track import VisualTrack, mean_row
from stabilize.progress import Progress, no_progress
from stabilize.settings import Settings
from stabilize.video import VideoError, VideoInfo, frame_times, read_frames
from stabilize.warp.lens import Lens, pinhole_map

ESTIMATE_CHUNK = 32  # flow fields held at once in pass 1
READOUT_BANDS = 6  # horizontal bands whose rotations date the rows (readout estimation)


def estimate_rotations(
    path: str | Path,
    info: VideoInfo,
    settings: Settings,
    progress: Progress = no_progress,
    times: NDArray | None = None,
    *,
    bands: int = 0,
    lens: Lens | None = None,
) -> VisualTrack:
    """Pass 1: the clip's rotations, frames streamed at the working size.

    Frame times are the container's timestamps unless given (e.g. from a sensor log).
    ``bands`` > 0 also estimates each pair's rotation from that many horizontal bands of
    the frame alone (for the rolling-shutter readout; about 0.5 ms per band and pair).
    With a fisheye ``lens`` the frames are first remapped to a pinhole view.
    """
    times = frame_times(path, info.input_args) if times is None else np.asarray(times)
    if len(times) < 2:
        raise VideoError(f"{path}: has {len(times)} frame(s); nothing to stabilise")
    ws = flow.working_size(info.size)
    backend = flow.get(settings.flow, **settings.flow_options)
    estimator, frames = _estimator_and_frames(path, info, settings, ws, lens)
    found = _vote(estimator, backend.many(frames), ws.size[0], bands, progress)
    n = len(found[0]) + 1
    if n < 2:
        raise VideoError(f"{path}: fewer than two frames decoded; nothing to stabilise")
    if n < len(times) - 1:
        raise VideoError(
            f"{path}: truncated or damaged: the container lists {len(times)} frames, "
            f"only {n} decode"
        )
    if len(times) != n:  # a frame's worth of slack for containers that list one extra
        times = times[:n] if len(times) > n else np.arange(n) / max(info.fps, 1.0)
    R, support, rows = (np.array([item[i] for item in found[0]]) for i in range(3))
    if not bands:
        return VisualTrack(times, R, support, rows)
    R_b, support_b, rows_b = (
        np.stack([np.array([item[i] for item in found[b]]) for b in range(1, bands + 1)])
        for i in range(3)
    )
    return VisualTrack(times, R, support, rows, R_b, rows_b, support_b)


def _estimator_and_frames(
    path: str | Path, info: VideoInfo, settings: Settings, ws: WorkingSize, lens: Lens | None
) -> tuple[HoughEstimator, Iterator[NDArray]]:
    """The estimator at the working size, and the frames it sees: the decoded frames, or
    through a fisheye ``lens``, their pinhole view."""
    frames = read_frames(path, ws.size, info)
    if lens is None:
        focal = settings.focal_px(info.width) * ws.scale[0]
        return HoughEstimator(ws.size, focal, max_deg=settings.max_deg), frames
    K_ws = scale_intrinsics(lens.K, *ws.scale)
    focal, center = float(K_ws[0, 0]), (float(K_ws[0, 2]), float(K_ws[1, 2]))
    estimator = HoughEstimator(ws.size, focal, center=center, max_deg=settings.max_deg)
    maps = pinhole_map(replace(lens, K=K_ws), ws.size, focal, center)
    return estimator, (cv2.remap(f, *maps, cv2.INTER_LINEAR) for f in frames)


def _vote(
    estimator: HoughEstimator, flows: Iterator[NDArray], height: int, bands: int, progress: Progress
) -> list[list[tuple]]:
    """(R, support, mean row) per pair: from the whole frame, then from each band."""
    sample_rows = estimator.grid.rows
    edges = np.linspace(0, height, bands + 1).round().astype(int)
    found: list[list[tuple]] = [[] for _ in range(bands + 1)]  # whole frame, then bands
    chunk: list[NDArray] = []

    def flush() -> None:
        stacked = np.stack(chunk)
        for b in range(bands + 1):
            if b:  # only this band's vectors vote
                stacked = np.stack(chunk)
                stacked[:, : edges[b - 1]] = np.nan
                stacked[:, edges[b] :] = np.nan
            for est in estimator.estimate_many(stacked):
                found[b].append((est.matrix, est.support, mean_row(est, sample_rows, height)))
        progress(len(chunk))
        chunk.clear()

    for f in flows:
        chunk.append(f)
        if len(chunk) == ESTIMATE_CHUNK:
            flush()
    if chunk:
        flush()
    return found
