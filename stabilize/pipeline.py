"""The stabiliser: two streaming passes over the video, memory independent of its length.

1. Decode at the flow's working size (~480 px), compute optical flow between
   consecutive frames, and estimate each pair's rotation R_t (:mod:`rotation`).
2. Chain the rotations into orientations O_t, smooth them on SO(3), fit the zoom
   budget, and choose the zoom (:mod:`stabilize.smoothing`, :mod:`stabilize.warping`).
3. Decode at full resolution, warp each frame by K' C_t K⁻¹, and encode, copying the
   audio untouched.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import asdict, dataclass, field, replace
from itertools import islice
from pathlib import Path

import cv2
import ffmpeg
import numpy as np
from numpy.typing import NDArray

import flow
from rotation import HoughEstimator, so3
from rotation.camera import focal_from_fov, intrinsics, scale_intrinsics
from stabilize import yuv
from stabilize.ffmpeg_tools import atomic_output
from stabilize.lens import Lens, pinhole_map, read_lens_profile
from stabilize.rolling_shutter import RollingShutter
from stabilize.smoothing import (
    gaussian_band,
    orientations_from_rotations,
    respect_zoom_budget,
    smooth_orientations,
)
from stabilize.track import VisualTrack, mean_row
from stabilize.video_reader import VideoError, VideoInfo, frame_times, probe, read_frames
from stabilize.video_writer import Encoding, FrameWriter, is_variable_rate, retime
from stabilize.warping import (
    frames_covered,
    homography,
    lens_source,
    remap_from,
    required_zooms,
    resize_image,
    rolling_source,
    warp_frame,
    warp_frames_torch,
)

# A phone's main camera is about 26 mm full-frame equivalent: 69° across the long side.
DEFAULT_HFOV = 69.0
CROP_MODES = ("auto", "dynamic", "none")
# Crop at most 13% of each side: about what FFmpeg's vid.stab zooms to (optzoom=1). Where
# removing all the shake would need more, the path keeps some of it (respect_zoom_budget);
# on our test clips that cost almost no steadiness (street: 0.943 → 0.942).
DEFAULT_MAX_ZOOM = 1.15
LOOSER = 0.35  # the smoothing time constant, as a share, of the path bent towards first
ESTIMATE_CHUNK = 32  # flow fields held at once in pass 1
WARP_BATCH = 8  # frames warped together on CUDA
READOUT_BANDS = 6  # horizontal bands whose rotations date the rows (readout estimation)


@dataclass(frozen=True)
class Settings:
    flow: str = "dis"
    flow_options: dict = field(default_factory=dict)
    fov: float | None = None
    focal: float | None = None
    smooth: float = 0.5
    method: str = "adaptive"
    max_zoom: float = DEFAULT_MAX_ZOOM
    crop: str = "auto"
    max_deg: float = 15.0
    preview: bool = False  # write original | stabilised side by side
    gyro: str | None = None  # a gyro log: the path comes from it, synchronised to the video
    gyro_format: str | None = None
    gyro_offset: float | None = None
    gyro_axes: tuple | None = None  # R_cam_imu as nested tuples
    gyro_lpf: float | None = None  # Hz
    readout_ms: float | str | None = None  # rolling shutter: ms, 'auto', or the log's value
    gyro_drift: bool = False  # also fit a linear clock drift
    lens: str | None = None  # a Gyroflow lens profile (OpenCV fisheye)
    device: str = "cpu"  # where frames are warped: cpu (OpenCV) or cuda (kornia, batched)
    size: tuple[int, int] | None = None  # output (H, W); default: the input's
    encoding: Encoding = field(default_factory=Encoding)

    def focal_px(self, width: int) -> float:
        if self.focal is not None:
            return float(self.focal)
        return focal_from_fov(self.fov or DEFAULT_HFOV, width)


@dataclass
class CameraPath:
    """The estimated and the planned camera path of a clip."""

    times: NDArray  # (N,) s
    rotations: NDArray  # (N-1, 3, 3) R_t
    support: NDArray  # (N-1,)
    raw: NDArray  # (N, 3, 3) O_t
    smooth: NDArray  # (N, 3, 3) S_t
    zoom: NDArray  # (N,) applied zoom
    homographies: NDArray  # (N, 3, 3) input → output pixels (the middle row's)
    K: NDArray
    # Rolling shutter: the corrections of each knot row (N, B, 3, 3) at input rows (B,).
    row_corrections: NDArray | None = None
    knot_rows: NDArray | None = None
    lens: Lens | None = None  # fisheye: frames are warped through it, not by homographies

    def warp_many(
        self, batch: Sequence[tuple[int, NDArray[np.uint8]]], device: str = "cpu"
    ) -> list[NDArray[np.uint8]]:
        """Output frames of (k, frame) pairs, RGB or I420 (2-D); on CUDA the plain
        homography warps run as one batch (lens and rolling-shutter maps stay on the CPU)."""
        plain = self.lens is None and self.row_corrections is None
        eight_bit = all(frame.dtype == np.uint8 for _, frame in batch)
        if not (device.startswith("cuda") and plain and eight_bit):
            return [self.warp(k, frame) for k, frame in batch]
        H = self.homographies[[k for k, _ in batch]]
        frames = np.stack([frame for _, frame in batch])
        if frames.ndim == 4:
            return list(warp_frames_torch(frames, H, device))
        planes = [np.stack(p) for p in zip(*(yuv.split(f) for f in frames), strict=True)]
        Hc = np.array([yuv.chroma_homography(h) for h in H])
        warped = [
            warp_frames_torch(p, M, device, fill)
            for p, M, fill in zip(planes, (H, Hc, Hc), yuv.black(frames), strict=True)
        ]
        return [yuv.join(*parts) for parts in zip(*warped, strict=True)]

    def warp(self, k: int, frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """Frame k of the output, from frame k of the input (RGB, or I420 when 2-D)."""
        planar = frame.ndim == 2
        rolling = self.row_corrections is not None
        if self.lens is None and not rolling:
            H = self.homographies[k]
            return yuv.warp(frame, H) if planar else warp_frame(frame, H)
        C = self.row_corrections[k] if rolling else self.smooth[k] @ self.raw[k].T
        if self.lens is not None:
            source = lens_source(self.lens, C, self.zoom[k], self.knot_rows)
        else:
            source = rolling_source(homography(self.K, C, self.zoom[k]), self.knot_rows)
        return yuv.remap(frame, source) if planar else remap_from(frame, source)


Progress = Callable[[int], None]


def _no_progress(_: int = 1) -> None:
    return None


def estimate_rotations(
    path: Path,
    info: VideoInfo,
    settings: Settings,
    progress: Progress = _no_progress,
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
    frames = read_frames(path, ws.size, info)
    if lens is None:
        focal = settings.focal_px(info.width) * ws.scale[0]
        estimator = HoughEstimator(ws.size, focal, max_deg=settings.max_deg)
    else:
        K_ws = scale_intrinsics(lens.K, *ws.scale)
        focal, center = float(K_ws[0, 0]), (float(K_ws[0, 2]), float(K_ws[1, 2]))
        estimator = HoughEstimator(ws.size, focal, center=center, max_deg=settings.max_deg)
        maps = pinhole_map(replace(lens, K=K_ws), ws.size, focal, center)
        frames = (cv2.remap(f, *maps, cv2.INTER_LINEAR) for f in frames)
    sample_rows = estimator.grid.rows
    height = ws.size[0]
    edges = np.linspace(0, height, bands + 1).round().astype(int)
    found: list[list[tuple]] = [[] for _ in range(bands + 1)]  # whole frame, then bands
    chunk: list[NDArray] = []

    def flush() -> None:
        flows = np.stack(chunk)
        for b in range(bands + 1):
            if b:  # only this band's vectors vote
                flows = np.stack(chunk)
                flows[:, : edges[b - 1]] = np.nan
                flows[:, edges[b] :] = np.nan
            for est in estimator.estimate_many(flows):
                found[b].append((est.matrix, est.support, mean_row(est, sample_rows, height)))
        progress(len(chunk))
        chunk.clear()

    for f in backend.many(frames):
        chunk.append(f)
        if len(chunk) == ESTIMATE_CHUNK:
            flush()
    if chunk:
        flush()
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


MIN_SUPPORT = 0.03  # below this share of agreeing vectors a frame's rotation is a guess
RELATIVE_SUPPORT = 0.35  # ...or below this fraction of the clip's median support
REPAIR_WINDOW = 3  # frames on each side whose rotations stand in for an unreliable one


def repair_unreliable(R: NDArray, support: NDArray) -> tuple[NDArray, NDArray]:
    """Replace the rotations that too few flow vectors agreed on.

    A close moving subject can fill the frame and win the vote with a handful of
    vectors; one such frame is a jump in the path that the smoothing then has to zoom
    around. Its rotation is replaced by the mean rotation vector of the reliable frames
    within ``REPAIR_WINDOW`` (or the nearest reliable one). Returns (R, reliable mask).
    """
    support = np.asarray(support)
    reliable = support >= max(MIN_SUPPORT, RELATIVE_SUPPORT * float(np.median(support)))
    if reliable.all() or not reliable.any():
        return R, np.ones(len(R), bool)
    rotvecs = so3.log_so3(R)
    good = np.flatnonzero(reliable)
    out = rotvecs.copy()
    for k in np.flatnonzero(~reliable):
        near = good[np.abs(good - k) <= REPAIR_WINDOW]
        if near.size == 0:
            near = good[[np.argmin(np.abs(good - k))]]
        out[k] = rotvecs[near].mean(axis=0)
    return so3.exp_so3(out), reliable


def plan(
    times: NDArray,
    rotations: NDArray,
    support: NDArray,
    K: NDArray,
    size: tuple[int, int],
    settings: Settings,
    rolling: RollingShutter | None = None,
    lens: Lens | None = None,
) -> CameraPath:
    """Smooth the path, keep it within the zoom budget, and choose each frame's zoom.

    With ``rolling``, each frame's correction also undoes the camera's turn between its
    middle row and every other row, C_t(y) = C_t D_t(y)ᵀ.
    """
    if settings.crop not in CROP_MODES:
        raise ValueError(f"crop must be one of {CROP_MODES}, got {settings.crop!r}")
    O = orientations_from_rotations(rotations)
    S = smooth_orientations(O, times, settings.smooth, settings.method)
    rows = None if rolling is None else rolling.rows

    def corrections(path: NDArray, frames: NDArray | slice = slice(None)) -> NDArray:
        C = path @ np.swapaxes(O[frames], -1, -2)
        if rolling is None:
            return C
        return C[:, None] @ np.swapaxes(rolling.turns[frames], -1, -2)

    def zoom_of(path: NDArray, frames: NDArray) -> NDArray:
        C = corrections(path, frames)
        return required_zooms(K, C, size, settings.max_zoom * 1.001, rows, lens)

    def over(path: NDArray, frames: NDArray) -> NDArray:
        zoom = np.full(len(frames), settings.max_zoom)
        return ~frames_covered(K, corrections(path, frames), zoom, size, rows, lens)

    if settings.crop == "none":
        need = np.ones(len(O))
    else:
        # Where the budget binds, first give up only the slow part of the smoothing.
        looser = smooth_orientations(O, times, settings.smooth * LOOSER, settings.method)
        S, need = respect_zoom_budget(
            O, S, times, zoom_of, settings.max_zoom, settings.smooth, via=(looser,), over=over
        )
    zoom = choose_zoom(need, times, settings)
    C = S @ np.swapaxes(O, -1, -2)
    H = np.array([homography(K, c, z) for c, z in zip(C, zoom, strict=True)])
    if rolling is None:
        return CameraPath(times, rotations, support, O, S, zoom, H, K, lens=lens)
    return CameraPath(times, rotations, support, O, S, zoom, H, K, corrections(S), rows, lens)


def choose_zoom(need: NDArray, times: NDArray, settings: Settings) -> NDArray:
    """auto: one zoom for the clip; dynamic: a smooth per-frame zoom ≥ need; none: 1."""
    need = np.minimum(need, settings.max_zoom)
    if settings.crop == "none":
        return np.ones_like(need)
    if settings.crop == "auto":
        return np.full_like(need, need.max())
    # The upper envelope of a Gaussian bump 1 + (need_j - 1) g(t - t_j) around every
    # frame: never below any frame's need, and it eases in and out of each one.
    # Each bump is cut at 4σ (where it is down to 3e-4 of its height).
    bumps = gaussian_band(times, max(settings.smooth, 0.1))
    heights = 1.0 + (need[bumps.indices] - 1.0) * bumps.data
    return np.maximum.reduceat(heights, bumps.indptr[:-1])


def render(
    path: Path,
    out: Path,
    info: VideoInfo,
    planned: CameraPath,
    settings: Settings,
    progress: Progress = _no_progress,
) -> int:
    """Pass 2: decode, warp, encode with the audio copied; returns frames written.

    A variable-frame-rate clip is encoded at its nominal rate without B-frames, then its
    packets are restamped with the source's own frame times (:func:`retime`).
    """
    audio = ffmpeg.input(str(path)).audio if info.has_audio else None
    written = 0
    fps = info.fps or 30.0
    h, w = settings.size or info.size
    size = (h, 2 * w) if settings.preview else (h, w)
    variable = is_variable_rate(planned.times)
    encoding = replace(settings.encoding, b_frames=False) if variable else settings.encoding
    target = out.with_name(out.name + ".cfr.mp4") if variable else out
    # I420 end to end where the size allows: no colour conversions, half the bytes.
    planar = yuv.supports(info.size) and yuv.supports((h, w))
    pix_fmt = yuv.pipe_format(info.pix_fmt) if planar else "rgb24"
    if pix_fmt == "yuv420p10le" and encoding.pix_fmt == "yuv420p":
        encoding = replace(encoding, pix_fmt=pix_fmt)  # keep a 10-bit source's depth
    side_by_side = yuv.hstack if planar else lambda a, b: np.hstack([a, b])
    resize = yuv.resize if planar else resize_image
    try:
        with FrameWriter(
            target, size, fps, encoding, audio, copy_audio=True, pix_fmt_in=pix_fmt
        ) as writer:
            decoded = read_frames(path, info=info, pix_fmt=pix_fmt)
            frames = zip(range(len(planned.zoom)), decoded, strict=False)
            for batch in batches(frames, WARP_BATCH if settings.device == "cuda" else 1):
                for frame, warped in zip(
                    (f for _, f in batch), planned.warp_many(batch, settings.device), strict=True
                ):
                    if settings.size:
                        frame, warped = resize(frame, (h, w)), resize(warped, (h, w))
                    writer.write(side_by_side(frame, warped) if settings.preview else warped)
                    written += 1
                    progress(1)
        if variable:
            retime(target, out, planned.times[:written])
    finally:
        if variable:
            target.unlink(missing_ok=True)
    return written


def batches(items: Iterable, n: int) -> Iterator[list]:
    """Consecutive lists of n items (the last may be shorter)."""
    it = iter(items)
    while batch := list(islice(it, n)):
        yield batch


def _from_gyro(
    settings: Settings, track: VisualTrack, height: int, lens: Lens | None = None
) -> tuple[NDArray, RollingShutter | None, dict]:
    """R_t from the gyro log named in settings, synchronised against the visual estimate,
    and the per-row turns when the readout time is known (or estimated)."""
    from stabilize.gyro import read_gyro
    from stabilize.gyro.source import gyro_rotations, lowpass
    from stabilize.rolling_shutter import frame_rotations, row_turns

    log = read_gyro(settings.gyro, settings.gyro_format)
    if settings.gyro_lpf:
        log = lowpass(log, settings.gyro_lpf)
    axes = None if settings.gyro_axes is None else np.array(settings.gyro_axes, dtype=float)
    readout = readout_seconds(settings.readout_ms, log.readout_s or (lens and lens.readout_s))
    att, sync = gyro_rotations(
        log,
        track,
        offset=settings.gyro_offset,
        R_cam_imu=axes,
        readout=readout,
        fit_drift=settings.gyro_drift,
    )
    clock = sync.clock(track.times)
    R = frame_rotations(att, clock, sync.offset, sync.readout)
    rolling = row_turns(att, clock, sync.offset, sync.readout, height) if sync.readout else None
    return (
        R,
        rolling,
        {
            "log": str(settings.gyro),
            "offset_s": sync.offset,
            "R_cam_imu": sync.R_cam_imu.tolist(),
            "speed_correlation": sync.correlation,
            "rate_hz": log.rate_hz,
            "readout_ms": 1000.0 * sync.readout,
            "readout_estimated": sync.readout_estimated,
        },
    )


def readout_seconds(option: float | str | None, from_log: float | None) -> float | None:
    """The readout to use: ``--readout-ms`` (a number, or 'auto': estimate it), else the
    log's own value, else 0 (no rolling-shutter correction). None means 'estimate'."""
    if option is None:
        return from_log or 0.0
    if option == "auto":
        return None
    value = float(option)
    if not 0.0 <= value < 1000.0:
        raise ValueError(f"--readout-ms must be between 0 and 1000 ms, got {option}")
    return value / 1000.0


def stabilize_video(
    input_path: str | os.PathLike,
    output_path: str | os.PathLike,
    settings: Settings | None = None,
    *,
    overwrite: bool = False,
    progress: Callable[[str, int | None], Progress] | None = None,
) -> tuple[dict, CameraPath]:
    """Stabilise a clip into ``output_path`` (atomically); returns (summary, path)."""
    settings = settings or Settings()
    src, dst = Path(input_path), Path(output_path)
    same = src.resolve() == dst.resolve() or (dst.exists() and os.path.samefile(src, dst))
    if same:
        raise ValueError(f"the output {dst} is the input; choose another name")
    if dst.exists() and not overwrite:
        raise FileExistsError(f"{dst} exists (use --overwrite to replace it)")
    info = probe(src)
    start = time.perf_counter()
    bar = progress or (lambda label, total: _no_progress)
    lens = read_lens_profile(settings.lens, info.size) if settings.lens else None
    bands = READOUT_BANDS if settings.gyro and settings.readout_ms == "auto" else 0
    times = frame_times(src, info.input_args)
    estimating = bar("estimating", max(len(times) - 1, 0))
    track = estimate_rotations(src, info, settings, estimating, times, bands=bands, lens=lens)
    times, support = track.times, track.support
    gyro_summary, rolling = None, None
    if settings.gyro:
        R, rolling, gyro_summary = _from_gyro(settings, track, info.height, lens)
    else:
        R, reliable = repair_unreliable(track.rotations, support)
    t_estimate = time.perf_counter() - start
    if lens is None:
        K = intrinsics(settings.focal_px(info.width), info.size)
    else:  # the homographies reported are the pinhole part of the lens
        K = intrinsics(lens.K[0, 0], info.size, (lens.K[0, 2], lens.K[1, 2]))
    planned = plan(times, R, support, K, info.size, settings, rolling, lens)
    t_plan = time.perf_counter() - start - t_estimate
    with atomic_output(dst, overwrite=overwrite) as tmp:
        frames = render(src, tmp, info, planned, settings, bar("stabilising", len(times)))
    total = time.perf_counter() - start
    summary = {
        "input": str(src),
        "output": str(dst),
        "frames": frames,
        "size": [info.width, info.height],
        "focal_px": float(K[0, 0]),
        "zoom": float(planned.zoom.max()),
        "mean_support": float(np.mean(support)),
        "repaired_frames": 0 if settings.gyro else int((~reliable).sum()),
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
    }
    return summary, planned
