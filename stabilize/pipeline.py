"""The job: stabilise one clip, in two streaming passes, memory independent of its length.

1. **Motion** (pass 1): decode at the flow's working size (~480 px), compute optical flow
   between consecutive frames, and estimate each pair's rotation R_t
   (:mod:`stabilize.motion`); repair the frames too few vectors agreed on, or take the
   rotations from a gyro log instead (:mod:`stabilize.gyro`).
2. **Path**: chain the rotations into orientations O_t, smooth them on SO(3), keep them
   within the zoom budget, and choose the zoom (:mod:`stabilize.path`).
3. **Warp** (pass 2): decode at full resolution, warp each frame by K' C_t K⁻¹, and
   encode, copying the audio untouched (:mod:`stabilize.warp`, :mod:`stabilize.video`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from rotation.camera import intrinsics
from stabilize.motion.estimate import READOUT_BANDS, estimate_rotations
from stabilize.motion.repair import repair_unreliable
from stabilize.path.plan import plan_path
from stabilize.progress import ProgressFactory, no_progress
from stabilize.settings import Settings
from stabilize.video import VideoInfo, atomic_output, frame_times, probe
from stabilize.video.containers import container_for
from stabilize.video.streams import keep_streams
from stabilize.warp.camera_path import CameraPath
from stabilize.warp.lens import Lens, read_lens_profile
from stabilize.warp.render import render


def stabilize_video(
    input_path: str | os.PathLike,
    output_path: str | os.PathLike,
    settings: Settings | None = None,
    *,
    overwrite: bool = False,
    progress: ProgressFactory | None = None,
    notify: Callable[[str], None] | None = None,
) -> tuple[dict, CameraPath]:
    """Stabilise a clip into ``output_path`` (atomically); returns (summary, path).

    The output's suffix chooses its container; every audio and subtitle track, the
    chapters and the metadata are kept (:func:`stabilize.video.streams.keep_streams`).
    ``progress(label, total)`` gives each long stage its callback (``"estimating"``, then
    ``"stabilising"``); ``notify`` hears, before any work, of each track that had to be
    converted or left out.
    """
    settings = settings or Settings()
    src, dst = Path(input_path), Path(output_path)
    _check_output(src, dst, overwrite)
    info = probe(src)
    mux = keep_streams(info, container_for(dst), info.video_delay)
    for notice in mux.notices:
        (notify or (lambda _: None))(notice)
    start = time.perf_counter()
    bar = progress or (lambda label, total: no_progress)
    lens = read_lens_profile(settings.lens, info.size) if settings.lens else None
    bands = READOUT_BANDS if settings.gyro and settings.readout_ms == "auto" else 0
    times = frame_times(src, info.input_args)
    estimating = bar("estimating", max(len(times) - 1, 0))
    track = estimate_rotations(src, info, settings, estimating, times, bands=bands, lens=lens)
    gyro_summary, rolling, repaired = None, None, 0
    if settings.gyro:
        from stabilize.gyro.path import gyro_path  # gyro mode only

        R, rolling, gyro_summary = gyro_path(settings, track, info.height, lens)
    else:
        R, reliable = repair_unreliable(track.rotations, track.support)
        repaired = int((~reliable).sum())
    t_estimate = time.perf_counter() - start
    K = _camera_matrix(settings, info, lens)
    planned = plan_path(track.times, R, track.support, K, info.size, settings, rolling, lens)
    t_plan = time.perf_counter() - start - t_estimate
    with atomic_output(dst, overwrite=overwrite) as tmp:
        frames = render(
            src, tmp, info, planned, settings, bar("stabilising", len(track.times)), mux
        )
    total = time.perf_counter() - start
    summary = {
        "input": str(src),
        "output": str(dst),
        "frames": frames,
        "size": [info.width, info.height],
        "focal_px": float(K[0, 0]),
        "zoom": float(planned.zoom.max()),
        "mean_support": float(np.mean(track.support)),
        "repaired_frames": repaired,
        "mean_rotation_deg": float(np.degrees(so3.angle(R)).mean()),
        "seconds": {
            "estimate": t_estimate,
            "plan": t_plan,
            "render": total - t_estimate - t_plan,
            "total": total,
        },
        "fps": frames / total,
        "settings": {k: v for k, v in asdict(settings).items() if k != "encoding"},
        "gyro": gyro_summary,
        "notices": list(mux.notices),
    }
    return summary, planned


def _check_output(src: Path, dst: Path, overwrite: bool) -> None:
    """Refuse an output that is the input, or that exists without ``overwrite``."""
    same = src.resolve() == dst.resolve() or (dst.exists() and os.path.samefile(src, dst))
    if same:
        raise ValueError(f"the output {dst} is the input; choose another name")
    if dst.exists() and not overwrite:
        raise FileExistsError(f"{dst} exists (use --overwrite to replace it)")


def _camera_matrix(settings: Settings, info: VideoInfo, lens: Lens | None) -> NDArray:
    """K at the video's size: from the settings' focal length, or the pinhole part of the
    lens profile (the homographies reported are then that part's)."""
    if lens is None:
        return intrinsics(settings.focal_px(info.width), info.size)
    return intrinsics(lens.K[0, 0], info.size, (lens.K[0, 2], lens.K[1, 2]))
