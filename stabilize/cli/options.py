"""The options that several commands share, declared once, with their defaults taken
from :data:`stabilize.settings.DEFAULTS`; and how parsed options become
:class:`~stabilize.settings.Settings`.

typer needs each command's full signature, so ``run`` and ``batch`` list these names
again, as ``name: XOption = DEFAULTS.name``; their values reach :func:`job_settings`
through click's ``ctx.params``, never listed a second time.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from stabilize.cli.app import fail
from stabilize.settings import Settings
from stabilize.video.encode import Encoding

FlowOption = Annotated[
    str, typer.Option("--flow", help="Optical flow: dis (fast, CPU), raft or raft-large.")
]
RaftWeightsOption = Annotated[Path | None, typer.Option(help="RAFT checkpoint (.pth).")]
DeviceOption = Annotated[str, typer.Option(help="cpu or cuda: RAFT flow and the frame warps.")]
FovOption = Annotated[
    float | None,
    typer.Option(help="Horizontal field of view, deg (default 69: a phone's main camera)."),
]
FocalOption = Annotated[
    float | None, typer.Option(help="Focal length in pixels (overrides --fov).")
]
LensOption = Annotated[
    Path | None,
    typer.Option(help="Gyroflow lens profile (.json, OpenCV fisheye): overrides --fov/--focal."),
]
SmoothOption = Annotated[float, typer.Option(min=0.01, help="Smoothing time constant, s.")]
MethodOption = Annotated[str, typer.Option(help="adaptive (follows pans) or gaussian.")]
LockOption = Annotated[bool, typer.Option(help="Hold one orientation, like a tripod.")]
MaxZoomOption = Annotated[float, typer.Option(min=1.0, help="Never zoom in more than this.")]
CropOption = Annotated[str, typer.Option(help="auto (one zoom), dynamic (smoothly varying), none.")]
CodecOption = Annotated[str, typer.Option(help="libx264 or libx265.")]
CrfOption = Annotated[int, typer.Option(min=0, max=51, help="Encoder quality (lower is better).")]
PresetOption = Annotated[str, typer.Option(help="Encoder speed preset.")]
PreviewOption = Annotated[
    str, typer.Option(help="side-by-side: the original and the stabilised clip next to each other.")
]
SizeOption = Annotated[str | None, typer.Option(help="Output WIDTHxHEIGHT (default: the input's).")]
GyroFormatOption = Annotated[str | None, typer.Option(help="Override the detected log format.")]
GyroLpfOption = Annotated[float | None, typer.Option(help="Low-pass the gyro at this many Hz.")]
GyroDriftOption = Annotated[bool, typer.Option("--gyro-drift", help="Also fit a clock drift.")]
ReadoutOption = Annotated[
    str | None,
    typer.Option(
        help="Rolling-shutter readout, ms, or 'auto' to estimate it (with a gyro log). "
        "Default: the log's own value, else none."
    ),
]
OverwriteOption = Annotated[bool, typer.Option(help="Replace the output if it exists.")]
QuietOption = Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")]
JsonOption = Annotated[bool, typer.Option("--json", help="Print the summary as JSON on stdout.")]

# The defaults of the options above that are not Settings fields by the same name.
ENCODING = Encoding()
NO_PREVIEW = "none"


def job_settings(params: Mapping[str, Any]) -> Settings:
    """The pipeline's Settings from the options ``run`` and ``batch`` share: a command's
    ``ctx.params``. Options the command does not have keep their defaults."""
    preview = params.get("preview", NO_PREVIEW)
    if preview not in (NO_PREVIEW, "side-by-side"):
        fail(f"--preview must be none or side-by-side, got {preview!r}")
    gyro = params.get("gyro")
    axes = params.get("gyro_axes")
    lens = params.get("lens")
    return flow_settings(
        params["flow_name"],
        params["raft_weights"],
        params["device"],
        fov=params["fov"],
        focal=params["focal"],
        smooth=params["smooth"],
        method="lock" if params["lock"] else params["method"],
        max_zoom=params["max_zoom"],
        crop=params["crop"],
        preview=preview == "side-by-side",
        size=output_size(params["size"]),
        encoding=Encoding(codec=params["codec"], crf=params["crf"], preset=params["preset"]),
        gyro=str(gyro) if gyro and gyro != "auto" else None,
        gyro_lpf=params["gyro_lpf"],
        readout_ms=readout(params["readout_ms"], gyro),
        gyro_drift=params["gyro_drift"],
        lens=str(lens) if lens else None,
        gyro_format=params["gyro_format"],
        gyro_offset=params.get("gyro_offset"),
        gyro_axes=None if axes is None else tuple(map(tuple, axes_matrix(axes))),
    )


def flow_settings(flow_name: str, raft_weights: Path | None, device: str, **options) -> Settings:
    """Settings with the flow backend and device checked; options are Settings fields
    (fov, smooth, crop, ...)."""
    if device not in ("cpu", "cuda"):
        fail(f"--device must be cpu or cuda, got {device!r}")
    if device == "cuda":
        import torch

        if not torch.cuda.is_available():
            fail("--device cuda was asked for, but torch sees no CUDA device")
    flow_options = {}
    if flow_name.startswith("raft"):
        flow_options = {"weights": raft_weights, "device": device}
    return Settings(flow=flow_name, flow_options=flow_options, device=device, **options)


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
    return h, w


def readout(value: str | None, gyro: object) -> float | str | None:
    """--readout-ms: a number of ms or 'auto'; rolling-shutter correction needs the gyro."""
    if value is not None and not gyro:
        fail("--readout-ms corrects the rolling shutter from the gyro: give --gyro LOG too")
    if value is None or value == "auto":
        return value
    try:
        return float(value)
    except ValueError:
        fail(f"--readout-ms takes a number of milliseconds or 'auto', got {value!r}")


def axes_matrix(code: str | None) -> np.ndarray | None:
    """--axes 'YXz' → R_cam_imu (:mod:`stabilize.gyro.axes`): camera x, y, z are IMU Y,
    X and -Z (lower case: negative)."""
    if code is None:
        return None
    from stabilize.gyro.axes import axes_matrix as parse
    from stabilize.gyro.log import GyroError

    try:
        return parse(code, what="--axes")
    except GyroError as err:
        fail(str(err))
