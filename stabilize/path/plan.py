"""Planning the camera path: smooth it, keep it within the zoom budget, choose the zoom.

Orientations O_{t+1} = R_t O_t are smoothed on SO(3) into S_t (:mod:`.smoothing`), and
the image motion each rotation leaves, chained into a 2-D path, is smoothed too
(:mod:`.residual`); the correction D_t S_t O_tᵀ of each frame needs some zoom to hide the
borders (:mod:`stabilize.warp.coverage`). The path is then the steadiest one near the
smoothed path within the crop (:mod:`.optimal`): within the budget where the smoothed
path needs more, else within the zoom the crop mode would spend on the smoothed path
anyway, so no more is cropped (should that programme fail, a path over the budget is
bent, :mod:`.budget`, and one within it kept). A held path (``--lock``) over the budget
is bent first, and the programme starts from its bend. Then the crop mode picks the
zoom (:mod:`.zoom`).

With a rolling shutter, each frame's correction also undoes the camera's turn between
its middle row and every other row, C_t(y) = C_t R_t(y)ᵀ.

An edited clip is planned shot by shot, each shot as a clip of its own (its path, its
zoom): no camera moves across a cut, and a path smoothed across one carries the motion of
one shot into the other.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from stabilize.motion.cuts import shots
from stabilize.path import residual as planar
from stabilize.path.budget import Trajectory, respect_zoom_budget
from stabilize.path.optimal import hold_at, image_metric, optimal_path
from stabilize.path.smoothing import orientations_from_rotations, smooth_orientations
from stabilize.path.zoom import CROP_MODES, choose_zoom
from stabilize.progress import Progress, no_progress
from stabilize.settings import Settings
from stabilize.video.decode import frame_interval
from stabilize.warp.camera_path import CameraPath
from stabilize.warp.coverage import CORNERS, Framing
from stabilize.warp.homography import homography
from stabilize.warp.lens import Lens
from stabilize.warp.rolling import RollingShutter

LOOSER = 0.35  # the smoothing time constant, as a share, of the path bent towards first
# how each shot's path was planned, the worst first: the joined path is called the worst
PLANNERS = ("bent", "optimal", "smoothed", "uncropped")


def plan_path(
    times: NDArray,
    rotations: NDArray,
    support: NDArray,
    K: NDArray,
    size: tuple[int, int],
    settings: Settings,
    rolling: RollingShutter | None = None,
    lens: Lens | None = None,
    residual: NDArray | None = None,
    cuts: NDArray | None = None,
    progress: Progress = no_progress,
) -> CameraPath:
    """The planned path of frames at ``times`` with rotations R_t (N-1, 3, 3), and the
    similarities (N-1, 4) they leave (``residual``; compensated as ``settings.motion``
    says), seen through K (3, 3), or each frame's (N, 3, 3; one for each shot). Pairs
    that ``cuts`` (N-1,) marks are changes of shot: each shot is planned on its own
    (:func:`stabilize.motion.cuts.shots`), and R_t across a cut only links the raw
    orientations.
    ``progress`` hears of the frames planned (a 10-minute clip's path takes about 13 s
    on this 2-core machine)."""
    if settings.crop not in CROP_MODES:
        raise ValueError(f"crop must be one of {tuple(CROP_MODES)}, got {settings.crop!r}")
    spans = shots(np.zeros(len(rotations), bool) if cuts is None else cuts)
    if len(spans) > 1:
        planned = [
            plan_path(
                times[first:stop],
                rotations[first : stop - 1],
                support[first : stop - 1],
                K[first] if K.ndim == 3 else K,
                size,
                settings,
                None if rolling is None else rolling.frames(first, stop),
                lens,
                None if residual is None else residual[first : stop - 1],
                progress=progress,
            )
            for first, stop in spans
        ]
        joined = _joined(planned, times, rotations, support)
        return replace(joined, shots=tuple(first for first, _ in spans))
    K = K[0] if K.ndim == 3 else K  # one shot, one camera
    measured = residual is not None and settings.motion != "rotation"
    if not measured:
        residual = np.zeros((len(rotations), 4))
    raw = Trajectory(orientations_from_rotations(rotations), planar.path_of(residual))
    held = settings.method == "lock"  # --lock: one orientation, the 2-D path held too
    O = raw.turn
    planned_so_far = 0

    def settled(frames: int) -> None:
        nonlocal planned_so_far
        if frames > planned_so_far:  # a second programme (the held path's) starts again
            progress(frames - planned_so_far)
            planned_so_far = frames

    def planned(smooth: float) -> Trajectory:
        S = smooth_orientations(O, times, smooth, settings.method)
        return Trajectory(S, planar.smooth_path(raw.shift, times, smooth, settings.motion, held))

    framing = Framing(K, size, None if rolling is None else rolling.rows, lens)
    # The stretch bound is the middle row's: a rolling shutter's shear undoes the one the
    # shutter made and has its own budget (rolling.within_stretch). Both in one bound,
    # the path had to bend against the shear where the shutter spent it: karma read
    # 0.549 px instead of 0.499, and max-heromode's middle third had no answer (bent)
    middle_row = Framing(K, size, None, lens)

    def turns(part: Trajectory, frames: NDArray | slice) -> tuple[NDArray, NDArray]:
        """(D_t, C_t) of ``frames``: their 2-D and 3-D corrections."""
        D = planar.corrections(raw.shift[frames], part.shift)
        return D, part.turn @ np.swapaxes(O[frames], -1, -2)

    def corrections(part: Trajectory, frames: NDArray | slice = slice(None)) -> NDArray:
        D, C = turns(part, frames)
        return D @ C if rolling is None else D[:, None] @ rolling.corrections(C, frames)

    def zoom_of(part: Trajectory, frames: NDArray) -> NDArray:
        return framing.required_zooms(corrections(part, frames), settings.max_zoom * 1.001)

    def over(part: Trajectory, frames: NDArray) -> NDArray:
        zoom = np.full(len(frames), settings.max_zoom)
        return ~framing.covered(corrections(part, frames), zoom)

    def steadiest(target: Trajectory, zoom: NDArray, over_budget: bool) -> Trajectory | None:
        """The steadiest path near ``target`` whose every frame covers the output at
        its ``zoom`` (:func:`optimal_path`), or None where the programme fails. Only a
        target ``over_budget`` can break it in a window's frames, so only its windows
        are looked at for the image's metric (a target within its zoom covers them all)."""

        def sources(part: Trajectory, frames: NDArray) -> NDArray:
            return framing.border_sources(corrections(part, frames), zoom[frames])

        def middle(part: Trajectory, frames: NDArray) -> NDArray:
            D, C = turns(part, frames)
            return middle_row.middle_jacobian(D @ C, zoom[frames])

        parts = planar.MOTION_MODELS[settings.motion] if measured else ()
        ceiling, sigma = _ceiling(raw, target, parts), settings.smooth / frame_interval(times)
        floor = 1 - settings.max_stretch / 100
        hold = hold_at(frame_interval(times))
        image = image_metric(parts, float(K[0, 0]), size[1]) if over_budget else None
        return optimal_path(
            target,
            sources,
            size,
            parts,
            CORNERS,
            ceiling,
            sigma,
            middle,
            floor,
            settled,
            hold,
            image,
        )

    path = planned(settings.smooth)
    everything = np.arange(len(O))
    planner = "smoothed"
    if settings.crop == "none":
        need, planner = np.ones(len(O)), "uncropped"
    elif over(path, everything).any():
        budget = np.full(len(O), settings.max_zoom)
        # A held path is planned from its bend (below) alone. Started from the held path,
        # far over the budget, the programme's rounds ended at paths less steady, and
        # slowly: with --lock (the means of four mirrored lossless readings) karma read
        # 0.557 px planned in 12 s, hero7 1.392 in 39 s, against 0.437 in 2.2 s and 1.208
        # in 1.6 s from the bend; on max-heromode it failed after 55 s, and its bend
        # planned the same 0.902 px in 0.6 s; phone-cc9 1.276 and 1.280, cockatoo 14.24
        # and 14.07 (distortion mirrored 0.984 / 0.979 and 0.977 / 0.968)
        solved = None
        if not held:
            solved = steadiest(path, budget, over_budget=True)
        if solved is not None:
            path, need, planner = solved, zoom_of(solved, everything), "optimal"
        else:
            # held, or the programme failed: bend, first giving up the smoothing's slow part
            looser = planned(settings.smooth * LOOSER)
            path, need = respect_zoom_budget(
                raw, path, times, zoom_of, settings.max_zoom, settings.smooth, (looser,), over
            )
            planner = "bent"
            if held:
                # A held path bends towards the raw one where it cannot hold, and covers:
                # the programme started there finds the steadiest path near it (with
                # --lock, max-heromode 1.239 -> 0.877 px, its middle third 2.318 -> 1.660,
                # cockatoo's middle half 21.24 -> 15.73). Not the smoothed path's bend:
                # cockatoo's middle third, at a focal length 3.6x too short, so planned
                # read 15.54 px at distortion 0.578 against 13.81 and 0.942 bent; and
                # planned from their bends, path_bench's violent clips read 3° 8.05 ->
                # 8.79 px, 4° 12.48 -> 14.61 (lossless, four mirrored readings' means)
                solved = steadiest(path, budget, over_budget=True)
                if solved is not None:
                    path, need, planner = solved, zoom_of(solved, everything), "optimal"
    else:
        need = zoom_of(path, everything)
        # The smoothed path fits, but the smoother leaves shake the crop it spends anyway
        # could hold: the steadiest path within that crop (each frame's zoom as the crop
        # mode would choose it) read 1.257 -> 1.109 px on phone-cc9's frames, 0.721 ->
        # 0.646 on the rendered 100 degree walk (means of the four mirrored readings).
        # A held path (--lock) is as steady as a path gets.
        if not held:
            spent = choose_zoom(need, times, settings.crop, settings.max_zoom, settings.smooth)
            solved = steadiest(path, spent, over_budget=False)
            if solved is not None:
                path, need, planner = solved, zoom_of(solved, everything), "optimal"
    zoom = choose_zoom(need, times, settings.crop, settings.max_zoom, settings.smooth)
    settled(len(O))
    D, C = turns(path, everything)
    H = homography(K, D @ C, zoom)  # the middle row's
    by_row = None if rolling is None else corrections(path)
    rows, S = framing.rows, path.turn
    return CameraPath(times, rotations, support, O, S, zoom, H, K, by_row, rows, lens, D, planner)


def _joined(
    planned: list[CameraPath], times: NDArray, rotations: NDArray, support: NDArray
) -> CameraPath:
    """The shots' paths as the clip's: the raw orientations O_t chained across the cuts
    (R_t there is its neighbours', :mod:`stabilize.motion.repair`), and each frame's
    planned S_t = (S'_t O'_tᵀ) O_t, the turn its shot planned (its path S', its raw O')
    applied to the clip's raw orientation."""

    def joined(name: str) -> NDArray:
        return np.concatenate([getattr(shot, name) for shot in planned])

    O = orientations_from_rotations(rotations)
    turns = joined("smooth") @ np.swapaxes(joined("raw"), -1, -2)
    first = planned[0]
    K = first.K
    if any(not np.array_equal(shot.K, K) for shot in planned):  # shots of two cameras
        K = np.concatenate([np.repeat(shot.K[None], len(shot.times), 0) for shot in planned])
    return CameraPath(
        times,
        rotations,
        support,
        O,
        turns @ O,
        joined("zoom"),
        joined("homographies"),
        K,
        None if first.row_corrections is None else joined("row_corrections"),
        first.knot_rows,
        first.lens,
        joined("shift"),
        min((shot.planner for shot in planned), key=PLANNERS.index),
    )


def _ceiling(raw: Trajectory, path: Trajectory, parts: tuple[int, ...]) -> NDArray:
    """Upper bounds on the optimiser's deviations: none, but the 2-D correction may
    never zoom in (the zoom alone spends the crop budget)."""
    ceiling = np.full((len(raw.turn), 3 + len(parts)), np.inf)
    if 3 in parts:
        ceiling[:, 3 + parts.index(3)] = raw.shift[:, 3] - path.shift[:, 3]
    return ceiling
