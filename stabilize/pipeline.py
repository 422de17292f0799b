"""The job: stabilise one clip, in two streaming passes, memory independent of its length.

1. **Motion** (pass 1): decode at the flow's working size (~480 px), compute optical flow
   between consecutive frames, and estimate each pair's rotation R_t
   (:mod:`stabilize.motion`); repair the frames too few vectors agreed on, or take the
   rotations from a gyro log instead (:mod:`stabilize.gyro`). Without a gyro, each
   pair's rotation is also measured on horizontal bands, which dates the rows of a
   rolling shutter: the readout, and the per-row turns, come from the video alone
   (:mod:`stabilize.shutter`).
2. **Path**: chain the rotations into orientations O_t, smooth them on SO(3), keep them
   within the zoom budget, and choose the zoom (:mod:`stabilize.path`).
3. **Warp** (pass 2): decode at full resolution, warp each frame by K' C_t K⁻¹, and
   encode into the container the output names, every track, chapter and tag of the
   source kept (:mod:`stabilize.warp`, :mod:`stabilize.video`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from threading import Thread
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

import flow
from rotation import so3
from rotation.camera import intrinsics
from rotation.hough import warm_up
from stabilize.gyro.log import GyroLog
from stabilize.motion.cuts import Breaks, said_cuts, track_breaks
from stabilize.motion.estimate import READOUT_BANDS, Damaged
from stabilize.motion.focal import FocalChoice, estimate_motion
from stabilize.motion.repair import repair_track
from stabilize.motion.residual import gate_px, reexpress
from stabilize.motion.track import VisualTrack
from stabilize.path.plan import plan_path
from stabilize.path.residual import MOTION_MODELS
from stabilize.path.smoothing import METHODS
from stabilize.path.zoom import CROP_MODES
from stabilize.progress import ProgressFactory, no_progress
from stabilize.settings import LENS_WITH_FOCAL, Settings
from stabilize.video import VideoInfo, atomic_output, frame_interval, frame_times, probe
from stabilize.video.atomic import check_absent, check_not_input, is_sequence
from stabilize.video.bars import BARS_MODES, detect_bars
from stabilize.video.binary import local
from stabilize.video.containers import container_for
from stabilize.video.encode import EncodeError, Encoding, Mux
from stabilize.video.encoders import unused_options
from stabilize.video.fields import DEINTERLACE_MODES, field_times
from stabilize.video.notices import (
    bars_notice,
    encoder_notice,
    fields_notice,
    pipe_notices,
    pixels_notice,
)
from stabilize.video.preflight import (
    check_encoder,
    check_pix_fmt,
    check_streams,
    check_times,
    check_writable,
    describe,
)
from stabilize.video.sequence import (
    first_image,
    is_pattern,
    picture,
    rate_notice,
    sequence_args,
    sequence_files,
)
from stabilize.video.streams import keep_streams
from stabilize.warp.border import BORDERS
from stabilize.warp.camera_path import CameraPath
from stabilize.warp.homography import cropping_ratio
from stabilize.warp.lens import Lens, read_lens_profile
from stabilize.warp.render import (
    check_shape,
    encoded_size,
    frame_size,
    output_encoding,
    render,
    shown_notice,
)
from stabilize.warp.rolling import RAMP_S, RollingShutter, within_stretch

if TYPE_CHECKING:
    from stabilize.shutter.readout import Readout


@dataclass(frozen=True)
class Job:
    """A checked job: everything known about it before any frame is decoded."""

    info: VideoInfo
    times: NDArray  # (N,) the frames' presentation times, s
    lens: Lens | None
    log: GyroLog | None
    stamps: NDArray | None  # the frames' times on the gyro clock (--gyro-timestamps)
    mux: Mux
    encoding: Encoding  # the output's encoder and pixel format, as the source's depth asks
    notices: tuple[str, ...]


@dataclass(frozen=True)
class Turns:
    """What pass 1 found, as the plan takes it (:func:`_rotations`)."""

    R: NDArray  # (N-1, 3, 3) each pair's rotation, between the frames' middle rows
    rolling: RollingShutter | None  # the rows' turns, under a rolling shutter
    residual: NDArray | None  # (N-1, 4) the similarities R_t leaves
    repaired: int  # frames whose rotation was taken from their neighbours
    gyro: dict | None  # the gyro's summary, where the rotations came from one
    shutter: Readout | None  # the visual readout, where measured
    eased: int  # frames whose row turns were eased within --max-stretch
    cuts: NDArray[np.bool_]  # (N-1,) the pairs across a change of shot


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
    Every option, the paths, the encoder and the gyro log are checked before any frame
    is decoded (:func:`prepare`). ``progress(label, total)`` gives each long stage its
    callback (``"estimating"``, then ``"stabilising"``); ``notify`` hears, before any
    work, of each track that had to be converted or left out.
    """
    settings = settings or Settings()
    src, dst = Path(input_path), Path(output_path)
    Thread(target=warm_up, name="warm-up", daemon=True).start()  # while FFmpeg probes
    job = prepare(src, dst, settings, overwrite)
    said = list(job.notices)  # and what the work finds: the summary's (and --json's) too
    heard = notify or (lambda _: None)

    def tell(message: str) -> None:
        said.append(message)
        heard(message)

    for notice in (*job.notices, *compiling_notice()):
        heard(notice)
    start = time.perf_counter()
    bar = progress or (lambda label, total: no_progress)
    try:
        track, focal, turns = _motion(src, job, settings, bar, tell)
    except Damaged as damage:  # refused before, however few frames were lost
        if job.stamps is not None:  # a sensor log's frame times count every frame
            raise
        times = damage.frames_that_decode(job.info)  # from the first listed frame's
        lead = float(times[0])  # the frames lost at the start: the video starts late
        mux = replace(job.mux, video_delay=job.mux.video_delay + lead)
        job = replace(job, times=times - lead, mux=mux)
        check_times(dst, job.times)  # its gaps make its rate vary: not into MXF
        tell(damage.notice)
        if lead > 0:
            tell(f"damaged: the first {lead:.2f} s of video do not decode: it starts there")
        track, focal, turns = _damaged_motion(src, job, settings, bar, tell, damage)
    t_estimate = time.perf_counter() - start
    K = _camera_matrices(focal, job.info, job.lens, len(track.times))
    planned = plan_path(
        track.times,
        turns.R,
        track.support,
        K,
        job.info.size,
        settings,
        turns.rolling,
        job.lens,
        turns.residual,
        turns.cuts,
        bar("planning", len(track.times)),
    )
    t_plan = time.perf_counter() - start - t_estimate
    if planned.planner == "bent":
        tell(
            "path: no steadiest path within the crop budget was found, so the smoothed one "
            "was bent towards the shaky one (a higher --max-zoom, or the right --fov, helps)"
        )
    frames = _write(
        src, dst, job, planned, settings, bar("stabilising", len(track.times)), overwrite
    )
    total = time.perf_counter() - start
    summary = {
        "input": str(src),
        "output": str(dst),
        "frames": frames,
        "size": list(job.info.shown_framed_size[::-1]),  # as shown, its bars included
        # counter-clockwise, degrees: the report's axes and pixels are the stored frames'
        "display_rotation": job.info.rotation,
        "display_mirror": job.info.mirror,
        "pixel_aspect": job.info.pixel_aspect,  # the input's; the output's pixels are square
        "bars": None if job.info.bars is None else list(job.info.bars),  # top, bottom, left, right
        "field_order": job.info.field_order or None,  # the input's: tff, bff, progressive
        "deinterlaced": job.info.deinterlace,
        "encoder": {"codec": job.encoding.codec, "pix_fmt": job.encoding.pix_fmt},
        "focal_px": float(focal.px if job.lens is None else job.lens.K[0, 0]),
        "focal": focal.summary(),
        "zoom": float(planned.zoom.max()),
        # the mean share of the frame's width kept about its middle, the 2-D correction's
        # zoom-outs included (evaluate's cropping ratio): 0.874-0.886 on the real clips at
        # zoom 1.15, where a static zoom's is 0.870
        "cropping_ratio": float(cropping_ratio(planned.homographies, job.info.size).mean()),
        "path": planned.planner,  # smoothed, optimal, bent or uncropped (CameraPath)
        # s, the first frame of each shot after the first, each planned on its own
        "cuts": [float(planned.times[k]) for k in planned.shots[1:]],
        "mean_support": float(np.mean(track.support)),
        "repaired_frames": turns.repaired,
        "mean_rotation_deg": float(np.degrees(so3.angle(turns.R)).mean()),
        "seconds": {
            "estimate": t_estimate,
            "plan": t_plan,
            "render": total - t_estimate - t_plan,
            "total": total,
        },
        "fps": frames / total,
        "settings": settings_summary(settings),
        "gyro": turns.gyro,
        "rolling_shutter": None if turns.shutter is None else turns.shutter.summary(),
        "stretch_eased_frames": turns.eased,  # row corrections kept within --max-stretch
        "notices": said,
    }
    return summary, planned


def prepare(src: Path, dst: Path, settings: Settings, overwrite: bool) -> Job:
    """Every check that can be made before decoding: the options, the input, the output
    folder, the encoder with these options in this container, the lens profile and the
    gyro log. Raises ValueError (its subclasses name the file) on the first problem."""
    _check_output(src, dst, overwrite)
    check_settings(settings)
    log = None
    if settings.gyro:  # first: reading a log takes milliseconds
        from stabilize.gyro.load import load_gyro

        log = load_gyro(settings)
    # the sensor's rows, whichever way the camera was held; its fields woven into frames
    info = probe(src, sequence_args(src, fps=settings.fps))
    info = info.stored().deinterlaced(settings.deinterlace)
    check_shape(info, settings)
    check_writable(dst)
    container = container_for(dst)
    encoding = output_encoding(info, settings, container)
    check_pix_fmt(encoding)
    check_encoder(dst, encoding, encoded_size(info, settings), info.fps or 30.0)
    lens = read_lens_profile(settings.lens, info.size) if settings.lens else None
    times = frame_times(src, info.input_args)  # read once: the packets, not the pixels
    stamps = None
    if settings.gyro_timestamps:
        from stabilize.gyro.readers import first_stamp, sensor_frame_times

        first = first_stamp(first_image(info.input_args))
        stamps = sensor_frame_times(settings.gyro_timestamps, first, len(times))
    if info.fields:  # a frame for each field, each at its own time
        times = field_times(times)
        stamps = None if stamps is None else field_times(stamps)
    check_times(dst, times)
    # Last, once every check has passed (it decodes frames): the picture inside black
    # bars baked into the frame. A lens's frame is the sensor's, bars or not.
    if settings.bars == "auto" and not settings.lens:
        info = info.within_bars(detect_bars(info))
    mux = keep_streams(info, container, info.video_delay)
    check_streams(dst, encoding, encoded_size(info, settings), mux, info.fps or 30.0)
    notices = rate_notice(src, settings.fps) + mux.notices + fields_notice(info)
    notices += pixels_notice(info) + bars_notice(info)
    if not container.timed:  # an image sequence: numbered as the input's, else from 1
        first = first_image(info.input_args)
        mux = replace(mux, args=(*mux.args, "-start_number", str(1 if first is None else first)))
        if first is None:
            notices += ("an image sequence keeps no frame times (--report's path.csv has them)",)
    notices += encoder_notice(encoding, settings.encoding.codec_for(container))
    notices += unused_options(encoding.codec, encoding.crf, encoding.preset)
    asked = settings.encoding.pix_fmt
    if asked not in (None, encoding.pix_fmt):  # a GIF's palette is its pixels
        name = container.name or container.muxer
        notices += (f"--pix-fmt {asked} has no effect on {name}: it writes {encoding.pix_fmt}",)
    notices += shown_notice(times, container)
    notices += pipe_notices(info, encoding, asked=asked is not None)
    if not settings.size and frame_size(info, settings) != info.shown_framed_size:
        (h, w), (sh, sw) = frame_size(info, settings), info.shown_framed_size
        notices += (
            f"{sw}x{sh} has an odd side: the output is {w}x{h}, the last row or column "
            "cropped (4:2:0 video needs even sides)",
        )
    return Job(info, times, lens, log, stamps, mux, encoding, notices)


COMPILING = "compiling the estimator's kernels"


def compiling_notice() -> tuple[str, ...]:
    """A notice, the first time only, that the estimator's kernels are being compiled."""
    from rotation.cache import cache_dir, kernels_cached

    if kernels_cached():
        return ()
    return (f"{COMPILING}: about 15 s, once (cached in {cache_dir()})",)


def dates_rows(settings: Settings, log: GyroLog | None = None, lens: Lens | None = None) -> bool:
    """Whether pass 1 also measures each band's rotations: to estimate the readout
    against the gyro (where neither the options, the ``log`` nor the ``lens`` profile
    give it), or to fit the visual attitude a rolling shutter is undone by."""
    visual = settings.rolling_shutter not in ("off", 0, 0.0)
    if settings.gyro:  # and, where the video may stand in for the log, as without one
        from stabilize.gyro.load import starting_readout

        from_log = log.readout_s if log is not None else None
        readout, _ = starting_readout(settings.readout_ms, from_log, lens and lens.readout_s)
        return readout is None or (settings.gyro_fallback and visual)
    return visual


def _damaged_motion(
    src: Path, job: Job, settings: Settings, bar, tell, damage: Damaged
) -> tuple[VisualTrack, FocalChoice, Turns]:
    """:func:`_motion` on a damaged clip's frames that decode; a gyro log they do not
    match is refused naming the damage, which no option of the log's cures."""
    from stabilize.gyro.log import GyroError

    try:
        return _motion(src, job, settings, bar, tell)
    except GyroError as err:
        # the frames decoded after a gap, from missing references, turn as garbage: the
        # rendered sample, damaged, read 2-6 degrees a frame there against 0.7
        lost = damage.listed - damage.decoded
        raise GyroError(
            f"{err} (the video is damaged: {lost} of its {damage.listed} frames do not "
            "decode, and those after them decode wrongly, which the match cannot see past; "
            "without --gyro it is stabilised from its own motion)"
        ) from None


def _motion(
    src: Path, job: Job, settings: Settings, bar, tell
) -> tuple[VisualTrack, FocalChoice, Turns]:
    """(track, focal length, :func:`_rotations`): pass 1, with its notices."""
    bands = READOUT_BANDS if dates_rows(settings, job.log, job.lens) else 0
    # the flow vectors (about 5 KB a pair): the repair checks a jump against them, and
    # they are measured again once a rolling shutter's rows are dated
    keep = job.log is None or settings.gyro_fallback
    estimating = bar("estimating", max(len(job.times) - 1, 0))
    track, focal = estimate_motion(
        src,
        job.info,
        settings,
        estimating,
        job.times,
        bands=bands,
        lens=job.lens,
        keep_samples=keep,
    )
    if job.log is not None:  # a gyro log is one camera's: its clip is warped through one K
        focal = replace(focal, shots=())
    for said in (focal.note, focal.said_shots(track.times)):
        if said:
            tell(f"focal length: {said}")
    return track, focal, _rotations(settings, job, track, focal, tell)


def _rotations(
    settings: Settings,
    job: Job,
    track: VisualTrack,
    choice: FocalChoice,
    tell: Callable[[str], None],
) -> Turns:
    """The clip's turns: from the gyro log when there is one, else the visual track with
    unreliable frames repaired (and no residual motion on them) and its cuts found; under
    a rolling shutter, the rotations between the frames' middle rows, and the row turns
    eased where they would stretch a frame past the budget
    (:func:`stabilize.warp.rolling.within_stretch`). Each shot is taken at its own focal
    length where it has one (:attr:`FocalChoice.shots`)."""
    focal = choice.px
    segments = _focal_segments(choice, len(track.times))
    reliable = np.ones(len(track.rotations), bool)
    cuts = np.zeros(len(track.rotations), bool)
    shutter = None
    from_gyro = _gyro_rotations(settings, job, track, tell)
    if from_gyro is not None:
        R, rolling, summary = from_gyro
    else:
        breaks = _breaks(track, tell)
        cuts = breaks.cuts
        per_pair = choice.per_frame(len(track.times))[:-1]
        R, reliable = repair_track(track, per_pair, breaks.unrelated)
        rolling, summary = None, None
        from stabilize.shutter import readout_for, visual_rolling_shutter

        shutter, spline = readout_for(settings.rolling_shutter, track, ~reliable)
        if shutter is not None and shutter.source != "off":
            tell(f"rolling shutter: {shutter.describe()}")
        if spline is not None:
            R, rolling = visual_rolling_shutter(
                spline, track.times, shutter.seconds, job.info.height
            )
    eased = 0
    if rolling is not None:
        ramp = round(RAMP_S / frame_interval(track.times))
        limit = settings.max_stretch
        eased_parts = [
            within_stretch(
                rolling.frames(first, stop),
                _camera_matrix(px, job.info, job.lens),
                ramp,
                1 - limit / 100,
            )
            for first, stop, px in segments
        ]
        rolling = RollingShutter(
            np.concatenate([part.turns for part, _ in eased_parts]), rolling.rows
        )
        eased = sum(count for _, count in eased_parts)
        if eased:
            tell(
                f"rolling shutter: the correction eased on {eased} of {len(track.times)} "
                f"frames, which it would have stretched by over {limit:g}% (--max-stretch)"
            )
    residual = track.residual
    if residual is not None and shutter is not None and rolling is not None:
        from stabilize.shutter.residual import rectified_residual

        gate = gate_px(track.times)  # pass 1's
        parts = [  # each shot's pairs, and the cut after it (whose residual is none)
            rectified_residual(
                track.samples.pairs(first, pairs),
                R[first:pairs],
                rolling.frames(first, pairs + 1),
                px,
                job.info.height,
                gate,
            )
            for first, pairs, px in _pair_segments(segments, len(R))
        ]
        # held to the strides of a high frame rate again (stabilize.motion.strides)
        residual = np.concatenate(parts) + (0.0 if track.held is None else track.held)
    elif residual is not None and from_gyro is not None:  # measured after the visual ones
        residual = reexpress(residual, track.rotations, R, focal, job.info.size)
    if residual is not None:
        residual = np.where(reliable[:, None], residual, 0.0)
    return Turns(R, rolling, residual, int((~reliable).sum()), summary, shutter, eased, cuts)


def _breaks(track: VisualTrack, tell: Callable[[str], None]) -> Breaks:
    """The track's breaks (:mod:`stabilize.motion.cuts`), its cuts said."""
    breaks = track_breaks(track)
    times = track.times[1:][breaks.cuts]  # the first frame of each new shot
    planned = "and each shot is planned on its own"
    if len(times) == 1:
        tell(f"{said_cuts(times)}: its turn is taken from the frames beside it, {planned}")
    elif len(times):
        tell(f"{said_cuts(times)}: their turns are taken from the frames beside them, {planned}")
    return breaks


def _gyro_rotations(
    settings: Settings, job: Job, track: VisualTrack, tell: Callable[[str], None]
) -> tuple | None:
    """(R_t, rolling-shutter turns or None, gyro summary) from the job's gyro log; None
    without one, or where it does not match the video and ``settings.gyro_fallback``
    lets the video's own motion be used instead (otherwise that is refused)."""
    if job.log is None:
        return None
    from stabilize.gyro.log import GyroError  # gyro mode only
    from stabilize.gyro.path import gyro_path
    from stabilize.gyro.sync import MOTION_SCALE

    try:
        gyro = gyro_path(settings, job.log, track, job.info.height, job.lens, job.stamps)
    except GyroError as err:
        if not settings.gyro_fallback:
            raise
        # its advice (--gyro-offset, --gyro-axes) is for one clip's log, not a camera's own
        reason = str(err).removeprefix(f"{job.log.source}: ").split("; ")[0]
        tell(f"gyro: not used, {reason}: stabilised from the video's own motion instead")
        return None
    scale = gyro[2]["motion_scale"]
    matches = MOTION_SCALE[0] <= scale <= MOTION_SCALE[1]
    if not matches and settings.gyro_fallback:
        # max-heromode's own gyro turns 6 times as far as its video, which the camera
        # steadied: stabilised from it, the clip would shake more than it does
        tell(
            f"gyro: not used, the video turns {scale:.2f} times as far as its gyro (a clip "
            "stabilised in the camera): stabilised from the video's own motion instead"
        )
        return None
    gyro = _with_readout(settings, job, track, gyro, tell)
    if not matches:
        tell(
            f"gyro: the video turns {scale:.2f} times as far as its gyro: a clip "
            "stabilised in the camera (the output may shake more than the input), or "
            "a focal length far off (--fov, --lens)"
        )
    return gyro


def _with_readout(
    settings: Settings, job: Job, track: VisualTrack, gyro: tuple, tell: Callable[[str], None]
) -> tuple:
    """The gyro path (R_t, rolling-shutter turns, summary), with a notice of a readout
    estimated; where the gyro did not pin it down, again at the readout the video's own
    bands read (:mod:`stabilize.shutter`). karma's smooth flight dates its bands too
    poorly against its gyro, yet its video reads 34.9 ± 1.5 ms, at which its gyro run
    read 0.495 px of residual shake against 0.532 uncorrected (0.513 from the video)."""
    from stabilize.gyro.log import GyroError
    from stabilize.gyro.path import gyro_path
    from stabilize.shutter import readout_for

    summary = gyro[2]
    if summary["readout_source"] == "estimated":
        found = f"{summary['readout_ms']:.1f} ms" if summary["readout_ms"] else "global shutter"
        tell(f"rolling shutter: {found} (estimated against the gyro)")
    if summary["readout_source"] != "none" or track.bands is None:
        return gyro
    readout, _ = readout_for("auto", track)
    said = f"rolling shutter: {readout.describe()}, from the video (the gyro does not pin it down)"
    if not readout.seconds:
        tell(said)
        return gyro
    again = replace(settings, readout_ms=1000.0 * readout.seconds)
    try:
        R, rolling, summary = gyro_path(
            again, job.log, track, job.info.height, job.lens, job.stamps
        )
    except GyroError as err:  # the first rows, dated earlier, may need more of the log
        tell(f"rolling shutter: not corrected: the video reads {readout.describe()}, but {err}")
        return gyro
    tell(said)
    return R, rolling, summary | {"readout_source": "video"}


def _write(
    src: Path, dst: Path, job: Job, planned: CameraPath, settings: Settings, progress, overwrite
) -> int:
    """Pass 2 into a temporary file beside ``dst``, renamed at the end; a failure names
    ``dst``, never the temporary file."""
    with atomic_output(dst, overwrite=overwrite) as tmp:
        try:
            return render(src, tmp, job.info, planned, settings, job.encoding, progress, job.mux)
        except EncodeError as err:
            named = str(err).replace(local(tmp), str(dst)).replace(str(tmp), str(dst))
            raise EncodeError(named) from None
        except OSError as err:
            raise EncodeError(f"cannot write {dst}: {describe(err)}") from None


def check_settings(settings: Settings) -> None:
    """Each setting within its range and among its choices; the error names the option."""
    checks = [
        (settings.flow in flow.BACKENDS, f"--flow must be one of {', '.join(flow.BACKENDS)}"),
        (settings.method in METHODS, f"--method must be one of {', '.join(METHODS)}"),
        (settings.crop in CROP_MODES, f"--crop must be one of {', '.join(CROP_MODES)}"),
        (settings.border in BORDERS, f"--border must be one of {', '.join(BORDERS)}"),
        (
            settings.motion in MOTION_MODELS,
            f"--motion must be one of {', '.join(MOTION_MODELS)}",
        ),
        (settings.device in ("cpu", "cuda"), "--device must be cpu or cuda"),
        (
            settings.deinterlace in DEINTERLACE_MODES,
            f"--deinterlace must be one of {', '.join(DEINTERLACE_MODES)}",
        ),
        (settings.bars in BARS_MODES, f"--bars must be one of {', '.join(BARS_MODES)}"),
        (
            settings.fov in (None, "auto")
            or (isinstance(settings.fov, int | float) and 0 < settings.fov < 180),
            "--fov must be 0–180° or auto",
        ),
        (settings.focal is None or settings.focal > 0, "--focal must be a positive number"),
        (settings.lens is None or not settings.fov_given, LENS_WITH_FOCAL),
        (settings.smooth > 0, "--smooth must be positive"),
        (settings.max_zoom >= 1.0, "--max-zoom must be at least 1"),
        (settings.gyro_search >= 0, "--gyro-search must not be negative"),
        (settings.fps is None or settings.fps > 0, "--fps must be positive"),
        (0 <= settings.max_stretch <= 100, "--max-stretch must be 0–100 %"),
        (
            settings.rolling_shutter in ("auto", "off")
            or (
                isinstance(settings.rolling_shutter, int | float)
                and 0 <= settings.rolling_shutter <= 1000
            ),
            "--rolling-shutter must be auto, off or 0–1000 ms",
        ),
        (
            settings.size is None or all(v % 2 == 0 for v in settings.size),
            "--size needs even sides (4:2:0 video)",
        ),
    ]
    for ok, message in checks:
        if not ok:
            raise ValueError(message)


def settings_summary(settings: Settings) -> dict:
    """The settings as JSON values (paths as strings), the encoder's too."""
    out = asdict(settings)
    out["flow_options"] = {
        k: str(v) if isinstance(v, os.PathLike) else v for k, v in settings.flow_options.items()
    }
    return out


def _check_output(src: Path, dst: Path, overwrite: bool) -> None:
    """Refuse an output that is the input, that would replace any of the input's
    pictures, that is standard output, or that exists without ``overwrite``."""
    if str(dst) == "-":  # it read "no suffix names its container ... (-.mp4)"
        raise ValueError(
            "OUT '-': a video is written to a file, named once it is whole, not to standard "
            "output: name one, e.g. steady.mp4"
        )
    if src.resolve() == dst.resolve():  # (an image sequence's pattern names no one file)
        raise ValueError(f"the output {dst} is the input; choose another name")
    check_not_input(dst, src)  # by another name: a link, another spelling
    if is_sequence(dst) and is_pattern(src):  # pictures beside pictures: none may be lost
        inputs = {p.resolve() for p in sequence_files(src).values()}
        replaced = {p.resolve() for p in sequence_files(dst).values()}  # with --overwrite
        replaced |= {picture(dst, n).resolve() for n in sequence_files(src)}  # its numbers
        if clash := sorted(inputs & replaced):
            raise ValueError(
                f"the output {dst} would replace the input's pictures ({clash[0].name}"
                f"{' and others' if len(clash) > 1 else ''}); choose another name or folder"
            )
    check_absent(dst, overwrite)


def _focal_segments(choice: FocalChoice, frames: int) -> list[tuple[int, int, float]]:
    """(first frame, stop, focal length px) of each run of frames at one focal length:
    the whole clip at the clip's, unless shots have their own (:attr:`FocalChoice.shots`)."""
    px = choice.per_frame(frames)
    starts = [0, *(np.flatnonzero(np.diff(px)) + 1).tolist()]
    stops = [*starts[1:], frames]
    return [(a, b, float(px[a])) for a, b in zip(starts, stops, strict=True)]


def _pair_segments(
    segments: list[tuple[int, int, float]], pairs: int
) -> list[tuple[int, int, float]]:
    """The frame ``segments`` as runs of pairs (first, stop, px): each takes the pair
    from its last frame into the next segment's first."""
    return [(first, min(stop, pairs), px) for first, stop, px in segments if first < pairs]


def _camera_matrices(choice: FocalChoice, info: VideoInfo, lens: Lens | None, frames: int):
    """K of the clip (3, 3), or of each of its ``frames`` frames (N, 3, 3) where shots
    have focal lengths of their own."""
    if not choice.shots or lens is not None:
        return _camera_matrix(choice.px, info, lens)
    return np.stack([_camera_matrix(px, info, None) for px in choice.per_frame(frames)])


def _camera_matrix(focal: float, info: VideoInfo, lens: Lens | None) -> NDArray:
    """K at the video's size: of the focal length (px), or the pinhole part of the lens
    profile (the homographies reported are then that part's)."""
    if lens is None:
        return intrinsics(focal, info.size)
    return intrinsics(lens.K[0, 0], info.size, (lens.K[0, 2], lens.K[1, 2]))
