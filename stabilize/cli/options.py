"""The options that several commands share, declared once, with their defaults taken
from :data:`stabilize.settings.DEFAULTS`; and how parsed options become
:class:`~stabilize.settings.Settings`.

typer needs each command's full signature, so ``run`` and ``batch`` list these names
again, as ``name: XOption = DEFAULTS.name``; their values reach :func:`job_settings`
through click's ``ctx.params``, never listed a second time.
"""

from __future__ import annotations

import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import typer

import flow
from stabilize.cli.app import fail
from stabilize.gyro.readers import FORMATS, GYRO_SIDECARS
from stabilize.path.residual import MOTION_MODELS
from stabilize.path.smoothing import METHODS
from stabilize.path.zoom import CROP_MODES
from stabilize.settings import DEFAULTS, Settings
from stabilize.video.bars import BARS_MODES
from stabilize.video.encode import Encoding
from stabilize.video.fields import DEINTERLACE_MODES
from stabilize.warp.border import BORDERS

FlowOption = Annotated[
    Literal[tuple(flow.BACKENDS)],
    typer.Option("--flow", help="Optical flow: dis (fast, CPU), raft or raft-large."),
]
RaftWeightsOption = Annotated[Path | None, typer.Option(help="RAFT checkpoint (.pth).")]
DeviceOption = Annotated[
    Literal["cpu", "cuda"], typer.Option(help="Where RAFT flow and the frame warps run.")
]
FovOption = Annotated[
    str | None,
    typer.Option(
        help="Field of view across the frame's long side (the horizontal one of a level "
        "frame, however the camera was held), degrees (1–179). Default (auto): estimated "
        "from the clip's own motion, starting from the file's metadata (a phone's 35 mm "
        "equivalent) or 69° (a phone's main camera), which stay where the motion does "
        "not pin it down, unless it rules them out (then the nearest it accepts).",
    ),
]
FocalOption = Annotated[
    float | None,
    typer.Option(min=1.0, help="Focal length in pixels (overrides --fov)."),
]
LensOption = Annotated[
    Path | None,
    typer.Option(
        help="Gyroflow lens profile (.json, OpenCV fisheye), with its own focal length "
        "(not with --fov or --focal)."
    ),
]
SmoothOption = Annotated[float, typer.Option(min=0.01, help="Smoothing time constant, s.")]
MethodOption = Annotated[
    Literal[tuple(METHODS)],
    typer.Option(help="adaptive (follows pans), gaussian, or lock (a tripod: one orientation)."),
]
MotionOption = Annotated[
    Literal[tuple(MOTION_MODELS)],
    typer.Option(
        help="What the warp compensates: the camera's rotation alone (exact for distant "
        "scenes), or also the image motion it leaves on the background (the vectors "
        "within about 1% of the frame's long side of where the rotation puts them): "
        "translation (a walk's sway past near surfaces), or similarity (also roll and "
        "zoom).",
    ),
]
LockOption = Annotated[bool, typer.Option(help="Hold one orientation, like a tripod.")]
MaxZoomOption = Annotated[
    float,
    typer.Option(
        min=1.0,
        help="Never zoom in more than this; where removing all the shake would need more, "
        "the path is the steadiest one within it (no border shows).",
    ),
]
CropOption = Annotated[
    Literal[tuple(CROP_MODES)],
    typer.Option(
        help="auto (one zoom), dynamic (smoothly varying), none (the frames' moving edges "
        "show: --border fills them)."
    ),
]
BorderOption = Annotated[
    Literal[tuple(BORDERS)],
    typer.Option(
        help="What shows where a frame has no source, which only --crop none lets into "
        "view: black, edge (its edge pixels repeated) or mirror (the frame reflected)."
    ),
]
CodecOption = Annotated[
    str | None,
    typer.Option(
        help="Video encoder (any FFmpeg has): default libx264, or libx265 for a source of "
        "10 bits or more (H.264 at 10 bits plays in few players), libvpx-vp9 for .webm, gif "
        "for .gif, mpeg2video for .mpg and .vob, libtheora for .ogv; "
        "libx265 for HEVC, libsvtav1 for AV1."
    ),
]
CrfOption = Annotated[
    int | None,
    typer.Option(
        min=0, max=63, help="Encoder quality, lower is better (default: 18 for x264, 31 VP9)."
    ),
]
PresetOption = Annotated[str, typer.Option(help="Encoder speed preset (x264's names).")]
PixFmtOption = Annotated[
    str | None,
    typer.Option(
        help="Pixel format written, FFmpeg's name (yuv422p10le, yuv444p, …; one the encoder "
        "writes). Default: 4:2:0 at the source's depth, which every player plays; ProRes's "
        "and DNxHR's own 4:2:2; a picture format's own. Colour finer than 4:2:0 reaches it "
        "whole."
    ),
]
DeinterlaceOption = Annotated[
    Literal[DEINTERLACE_MODES],
    typer.Option(
        help="Interlaced video (a camcorder's 50i, 60i): auto deinterlaces a stream flagged "
        "interlaced, on every stream (one flagged progressive but combed), off none; fields "
        "makes each field a frame of its own (50i → 50p, as a television shows it)."
    ),
]
BarsOption = Annotated[
    Literal[BARS_MODES],
    typer.Option(
        help="Black bars baked into the frame (letterbox, pillarbox): auto stabilises the "
        "picture inside them and keeps them still; off warps them with it."
    ),
]
PreviewOption = Annotated[
    Literal["none", "side-by-side"],
    typer.Option(help="side-by-side: the original and the stabilised clip next to each other."),
]
SizeOption = Annotated[
    str | None, typer.Option(help="Output WIDTHxHEIGHT, both even (default: the input's).")
]
FORMAT_HELP = ", ".join(FORMATS)
GyroFormatOption = Annotated[
    Literal[FORMATS] | None,
    typer.Option(help=f"The log's format, if not detected: {FORMAT_HELP}."),
]
GyroOffsetOption = Annotated[
    float | None, typer.Option("--gyro-offset", help="Gyro minus video clock, s (no search).")
]
GyroAxesOption = Annotated[
    str | None,
    typer.Option(
        "--gyro-axes",
        help="The IMU axis of camera x, y and z as three letters, e.g. YXz: camera x is "
        "IMU +Y, y is +X, z is -Z (lower case: the negative axis); the camera's axes as "
        "its sensor stores the frames, however the phone was held. Default: found.",
    ),
]
GyroSearchOption = Annotated[
    float,
    typer.Option(
        "--gyro-search",
        min=0.0,
        help="Offset search range, ± s; a log on its own clock is searched whole.",
    ),
]
GyroTimestampsOption = Annotated[
    Path | None,
    typer.Option(
        "--gyro-timestamps",
        help="Frame times on the gyro clock (OpenCamera ns, or seconds per line).",
    ),
]
FpsOption = Annotated[
    float | None,
    typer.Option(
        min=0.01, help="Frame rate of an image-sequence input (frames/img-%d.jpg); default 30."
    ),
]
GyroLpfOption = Annotated[float | None, typer.Option(help="Low-pass the gyro at this many Hz.")]
GyroDriftOption = Annotated[bool, typer.Option("--gyro-drift", help="Also fit a clock drift.")]
ReadoutOption = Annotated[
    str | None,
    typer.Option(
        help="Rolling-shutter readout, ms, or 'auto' to estimate it (with a gyro log). "
        "Default: the log's own value, else the lens profile's, else estimated against the "
        "gyro, else from the video alone."
    ),
]
MaxStretchOption = Annotated[
    float,
    typer.Option(
        "--max-stretch",
        min=0.0,
        max=100.0,
        help="The most the rolling-shutter correction may shear or stretch a frame, %; "
        "a frame whose rows turned further is corrected less (ramped over 0.15 s). "
        "The path's keystone at the frame's middle is kept within it too, apart. "
        "100: no limit.",
    ),
]
RollingShutterOption = Annotated[
    str,
    typer.Option(
        "--rolling-shutter",
        help="Rolling-shutter readout (top to bottom row), without a gyro: 'auto' estimates "
        "it from the video and corrects it when measured; 'off' treats the camera as "
        "global-shutter; or a number of ms. With --gyro a number or 'off' sets the readout "
        "as --readout-ms does.",
    ),
]
OverwriteOption = Annotated[bool, typer.Option(help="Replace the output if it exists.")]
QuietOption = Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")]
JsonOption = Annotated[bool, typer.Option("--json", help="Print the summary as JSON on stdout.")]
SIDECARS = ", ".join(GYRO_SIDECARS)

# The defaults of the options above that are not Settings fields by the same name.
ENCODING = Encoding()
NO_PREVIEW = "none"
GYRO_SEARCH = 1.0


def job_settings(params: Mapping[str, Any]) -> Settings:
    """The pipeline's Settings from the options ``run`` and ``batch`` share: a command's
    ``ctx.params``. Options the command does not have keep their defaults."""
    preview = params.get("preview", NO_PREVIEW)
    gyro = params.get("gyro")
    axes = params.get("gyro_axes")
    lens = params.get("lens")
    shutter = rolling_shutter(params.get("rolling_shutter", DEFAULTS.rolling_shutter))
    return flow_settings(
        params["flow_name"],
        params["raft_weights"],
        params["device"],
        fov=field_of_view(params["fov"]),
        focal=params["focal"],
        smooth=params["smooth"],
        method="lock" if params["lock"] else params["method"],
        motion=params["motion"],
        max_zoom=params["max_zoom"],
        crop=params["crop"],
        border=params.get("border", DEFAULTS.border),
        preview=preview == "side-by-side",
        size=output_size(params["size"]),
        deinterlace=params.get("deinterlace", DEFAULTS.deinterlace),
        bars=params.get("bars", DEFAULTS.bars),
        encoding=Encoding(
            codec=params["codec"],
            crf=params["crf"],
            preset=params["preset"],
            pix_fmt=params.get("pix_fmt"),
        ),
        gyro=str(gyro) if gyro and str(gyro) != "auto" else None,  # auto: the command's
        gyro_lpf=params["gyro_lpf"],
        readout_ms=readout(params["readout_ms"], gyro, shutter),
        rolling_shutter=shutter,
        max_stretch=params.get("max_stretch", DEFAULTS.max_stretch),
        gyro_drift=params["gyro_drift"],
        lens=str(lens) if lens else None,
        gyro_format=params["gyro_format"],
        gyro_offset=params.get("gyro_offset"),
        gyro_axes=None if axes is None else tuple(map(tuple, axes_matrix(axes))),
        gyro_timestamps=str(stamps) if (stamps := params.get("gyro_timestamps")) else None,
        gyro_search=params.get("gyro_search", GYRO_SEARCH),
        fps=params.get("fps"),
    )


def flow_settings(flow_name: str, raft_weights: Path | None, device: str, **options) -> Settings:
    """Settings with the flow backend and device checked; options are Settings fields
    (fov, smooth, crop, ...)."""
    if device == "cuda":
        if not (Path("/proc/driver/nvidia/version").exists() or shutil.which("nvidia-smi")):
            fail("--device cuda was asked for, but this machine has no NVIDIA driver")
        import torch  # about 1.5 s: only where a driver could answer

        if not torch.cuda.is_available():
            fail("--device cuda was asked for, but torch sees no CUDA device")
    flow_options = {}
    if flow_name.startswith("raft"):
        flow_options = {"weights": raft_weights, "device": device}
    return Settings(flow=flow_name, flow_options=flow_options, device=device, **options)


def field_of_view(text: str | None) -> float | str | None:
    """--fov: degrees across, between 1 and 179, or 'auto'."""
    return None if text is None else number_or_word(text, "--fov", ("auto",), (1.0, 179.0), "°")


def number_or_word(
    text: str, option: str, words: tuple[str, ...], bounds: tuple[float, float], unit: str
) -> float | str:
    """An option that takes one of ``words`` or a number within ``bounds``."""
    if text in words:
        return text
    lo, hi = bounds
    choices = " or ".join(repr(w) for w in words)
    try:
        value = float(text)
    except ValueError:
        fail(f"{option} takes a number ({lo:g}–{hi:g} {unit}) or {choices}, got {text!r}")
    if not lo <= value <= hi:
        fail(f"{option} must be between {lo:g} and {hi:g} {unit}, got {text}")
    return value


def output_size(text: str | None) -> tuple[int, int] | None:
    """--size WIDTHxHEIGHT → (H, W)."""
    if text is None:
        return None
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        fail(f"--size must be WIDTHxHEIGHT, e.g. 1280x720, got {text!r}")
    if w < 16 or h < 16 or w > 16384 or h > 16384:
        fail(f"--size {text}: each side must be 16..16384 pixels")
    if w % 2 or h % 2:
        fail(f"--size {text}: both sides must be even (4:2:0 video), e.g. {w - w % 2}x{h - h % 2}")
    return h, w


def rolling_shutter(value: str) -> float | str:
    """--rolling-shutter: 'auto', 'off', or a readout of 0..1000 ms."""
    return number_or_word(str(value), "--rolling-shutter", ("auto", "off"), (0.0, 1000.0), "ms")


def readout(value: str | None, gyro: object, shutter: float | str = "auto") -> float | str | None:
    """--readout-ms: a number of ms or 'auto'; rolling-shutter correction needs the gyro.
    With a gyro, --rolling-shutter's number (or 'off': 0) stands for it."""
    if value is not None and not gyro:
        fail(
            "--readout-ms corrects the rolling shutter from the gyro: give --gyro LOG too "
            "(without one, use --rolling-shutter)"
        )
    if gyro and shutter != "auto":
        if value is not None:
            fail("--readout-ms and --rolling-shutter both set the readout: give one")
        return 0.0 if shutter == "off" else shutter
    if value is None or value == "auto":
        return value
    try:
        return float(value)
    except ValueError:
        fail(f"--readout-ms takes a number of milliseconds or 'auto', got {value!r}")


def axes_matrix(code: str | None) -> np.ndarray | None:
    """--gyro-axes 'YXz' → R_cam_imu (:mod:`stabilize.gyro.axes`): camera x, y, z are IMU Y,
    X and -Z (lower case: negative)."""
    if code is None:
        return None
    from stabilize.gyro.axes import axes_matrix as parse
    from stabilize.gyro.log import GyroError

    try:
        return parse(code, what="--gyro-axes")
    except GyroError as err:
        fail(str(err))
