"""The ``stabilize`` command line: one typer app.

``stabilize IN OUT [options]`` is the main job; ``rotations``, ``synth``,
``evaluate``, ``compare`` and ``batch`` are subcommands, each added by the module
that implements it. This module is only the shell: version, help and dispatch.
"""

from __future__ import annotations

import contextlib
import inspect
import json
import sys
from dataclasses import replace
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Annotated, NoReturn

import numpy as np
import typer

app = typer.Typer(
    name="stabilize",
    help=(
        "Video stabilisation from a robust camera-rotation estimator "
        "(Hough transform on SO(3), ICCV 2023)."
    ),
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="markdown",
)


def package_version() -> str:
    try:
        return version("hough-stabilize")
    except PackageNotFoundError:  # running from a source tree that was not installed
        return "unknown"


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"stabilize {package_version()}")
        raise typer.Exit()


@app.callback()
def _root(
    version_flag: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Video stabilisation from a robust camera-rotation estimator."""


def _fail(message: str) -> NoReturn:
    """One clear line on stderr and a non-zero exit."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(2)


# Options that several commands take, defined once (each command gives the default).
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


def _job_settings(
    *,
    flow_name: str,
    raft_weights: Path | None,
    device: str,
    fov: float | None,
    focal: float | None,
    lens: Path | None,
    smooth: float,
    method: str,
    lock: bool,
    max_zoom: float,
    crop: str,
    codec: str,
    crf: int,
    preset: str,
    preview: str,
    size: str | None,
    readout_ms: str | None,
    gyro_lpf: float | None,
    gyro_drift: bool,
    gyro: Path | str | None,
    gyro_format: str | None,
    **gyro_options,
):
    """The pipeline's Settings from the options that ``run`` and ``batch`` share."""
    from stabilize.video_writer import Encoding

    if preview not in ("none", "side-by-side"):
        _fail(f"--preview must be none or side-by-side, got {preview!r}")
    return _settings(
        flow_name,
        raft_weights,
        device,
        fov=fov,
        focal=focal,
        smooth=smooth,
        method="lock" if lock else method,
        max_zoom=max_zoom,
        crop=crop,
        preview=preview == "side-by-side",
        size=_output_size(size),
        encoding=Encoding(codec=codec, crf=crf, preset=preset),
        gyro=str(gyro) if gyro and gyro != "auto" else None,
        gyro_lpf=gyro_lpf,
        readout_ms=_readout(readout_ms, gyro),
        gyro_drift=gyro_drift,
        lens=str(lens) if lens else None,
        gyro_format=gyro_format,
        **gyro_options,
    )


def _shared(arguments: dict) -> dict:
    """The options among a command's ``locals()`` that :func:`_job_settings` takes by name:
    ``run`` and ``batch`` hand them on without listing them twice."""
    params = inspect.signature(_job_settings).parameters.values()
    names = {p.name for p in params if p.kind is p.KEYWORD_ONLY}
    return {k: v for k, v in arguments.items() if k in names}


def _default_panorama() -> Path | None:
    """``../shared/data/panorama/meadow_cube.jpg`` beside the working directory or checkout."""
    here = Path(__file__).resolve().parents[1]
    for base in (Path.cwd(), here):
        candidate = base.parent / "shared" / "data" / "panorama" / "meadow_cube.jpg"
        if candidate.is_file():
            return candidate
    return None


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize synth out/street                      # 4 s, 960x540, 12 people\n\n"
        "  stabilize synth out/crowd --crowd 30 --shake-deg 2 --seed 7\n\n"
        "  stabilize synth out/rs --rolling-shutter-ms 25 --gyro-offset 0.08"
    )
)
def synth(
    out_dir: Path = typer.Argument(..., help="Folder to write clip.mp4, truth and gyro logs into."),
    seed: int = typer.Option(0, help="Random seed: the output depends only on the options."),
    seconds: float = typer.Option(4.0, min=0.1, help="Clip length."),
    fps: float = typer.Option(30.0, min=1.0, help="Frame rate."),
    size: str = typer.Option("960x540", help="WIDTHxHEIGHT."),
    hfov: float = typer.Option(70.0, min=10.0, max=150.0, help="Horizontal field of view, deg."),
    crowd: int = typer.Option(12, min=0, help="Number of walking people."),
    walls: bool = typer.Option(
        True, "--walls/--no-walls", help="Building fronts along the street."
    ),
    shake_deg: float = typer.Option(1.0, min=0.0, help="RMS hand shake per axis (1–9 Hz), deg."),
    pan_deg: float = typer.Option(10.0, help="Intentional pan over the clip, deg."),
    walk: float = typer.Option(1.0, min=0.0, help="Walking speed, m/s."),
    rolling_shutter_ms: float = typer.Option(0.0, min=0.0, help="Sensor readout time, ms."),
    gyro_offset: float = typer.Option(0.35, help="Gyro clock minus video clock, s."),
    background: Path | None = typer.Option(
        None,
        help="A cube-map image (default: ../shared's meadow_cube.jpg if present, "
        "else a procedural skyline).",
    ),
    procedural: bool = typer.Option(
        False, help="Use the procedural skyline even if the photograph is present."
    ),
    quiet: QuietOption = False,
) -> None:
    """Render a shaky handheld street clip whose every rotation is known, with its gyro log."""
    from stabilize.progress import progress_bar
    from stabilize.synth import SynthOptions, render_clip

    bg = None if procedural else (background or _default_panorama())
    if bg is not None and not Path(bg).is_file():
        _fail(f"background image not found: {bg}")
    opts = SynthOptions(
        seed=seed,
        seconds=seconds,
        fps=fps,
        size=_output_size(size),
        hfov=hfov,
        crowd=crowd,
        walls=walls,
        shake_deg=shake_deg,
        pan_deg=pan_deg,
        walk=walk,
        rolling_shutter_ms=rolling_shutter_ms,
        gyro_offset=gyro_offset,
        background=str(bg) if bg else None,
    )
    with progress_bar("rendering", opts.n_frames, unit="frames", quiet=quiet) as advance:
        summary = render_clip(out_dir, opts, advance)
    typer.echo(json.dumps(summary, indent=2))


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize evaluate shaky.mp4 steady.mp4\n\n"
        "  stabilize evaluate shaky.mp4 vidstab.mp4 --json > metrics.json\n\n"
        "  stabilize evaluate clip.mp4 out.mp4 --truth truth.csv --rotations rotations.csv"
    )
)
def evaluate(
    original: Path = typer.Argument(..., help="The input clip."),
    stabilised: Path = typer.Argument(..., help="Its stabilised version (from any tool)."),
    truth: Path | None = typer.Option(None, help="truth.csv of a rendered clip."),
    rotations: Path | None = typer.Option(
        None, help="An estimated rotations file (frame,t,rx,ry,rz,...) to score against --truth."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON on stdout."),
) -> None:
    """Cropping ratio, distortion, stability and ITF of a stabilised clip and its original."""
    from stabilize.metrics import evaluate_pair
    from stabilize.rotation_files import angular_errors, read_rotations
    from stabilize.video_reader import VideoError, probe, read_frames

    if (truth is None) != (rotations is None):
        _fail("--truth and --rotations go together")
    try:
        info_o, info_s = probe(original), probe(stabilised)
        size = info_o.size
        before, after = evaluate_pair(
            read_frames(original, info=info_o), read_frames(stabilised, size, info_s)
        )
        result = {"original": before.as_dict(), "stabilised": after.as_dict()}
        if truth is not None:
            err = angular_errors(read_rotations(rotations), read_rotations(truth))
            result["rotations"] = {
                "pairs": len(err),
                "aae_deg": float(err.mean()),
                "median_deg": float(np.median(err)),
                "p95_deg": float(np.percentile(err, 95)),
            }
    except (VideoError, ValueError) as err:
        _fail(str(err))
    if as_json:
        typer.echo(json.dumps(result, indent=2))
        return
    rows = [
        ("cropping ratio", "cropping_ratio", "{:.3f}"),
        ("distortion", "distortion", "{:.3f}"),
        ("stability (translation)", "stability_translation", "{:.3f}"),
        ("stability (rotation)", "stability_rotation", "{:.3f}"),
        ("stability", "stability", "{:.3f}"),
        ("ITF (dB)", "itf_db", "{:.2f}"),
        ("frames", "frames", "{}"),
    ]
    typer.echo(f"{'metric':26s}{'original':>12s}{'stabilised':>12s}")
    for label, key, fmt in rows:
        a, b = fmt.format(result["original"][key]), fmt.format(result["stabilised"][key])
        typer.echo(f"{label:26s}{a:>12s}{b:>12s}")
    if "rotations" in result:
        r = result["rotations"]
        typer.echo(
            f"rotation error vs truth: AAE {r['aae_deg']:.4f}°, median "
            f"{r['median_deg']:.4f}°, p95 {r['p95_deg']:.4f}° over {r['pairs']} pairs"
        )


def _settings(flow_name: str, raft_weights: Path | None, device: str, **options):
    """Settings for the pipeline; options are Settings fields (fov, smooth, crop, ...)."""
    from stabilize.pipeline import Settings

    if device not in ("cpu", "cuda"):
        _fail(f"--device must be cpu or cuda, got {device!r}")
    if device == "cuda":
        import torch

        if not torch.cuda.is_available():
            _fail("--device cuda was asked for, but torch sees no CUDA device")
    flow_options = {}
    if flow_name.startswith("raft"):
        flow_options = {"weights": raft_weights, "device": device}
    return Settings(flow=flow_name, flow_options=flow_options, device=device, **options)


FOCAL_ROUNDS = 3  # re-estimations when fitting the focal length to the gyro


@app.command(
    "run",
    epilog=(
        "The main job; `stabilize IN OUT` is short for `stabilize run IN OUT`.\n\n"
        "Examples:\n\n"
        "  stabilize shaky.mp4 steady.mp4\n\n"
        "  stabilize shaky.mp4 steady.mp4 --smooth 1.0 --max-zoom 1.3 --report report/\n\n"
        "  stabilize drone.mp4 locked.mp4 --lock --crop dynamic\n\n"
        "  stabilize gopro.mp4 out.mp4 --lens 'GoPro_HERO7 Black_Wide_16by9.json'\n\n"
        "  stabilize in.mp4 out.mp4 --flow raft --raft-weights raft-small.pth --device cuda"
    ),
)
def run(
    input_path: Path = typer.Argument(..., metavar="IN", help="The shaky video."),
    output_path: Path = typer.Argument(..., metavar="OUT", help="Where to write the result."),
    flow_name: FlowOption = "dis",
    raft_weights: RaftWeightsOption = None,
    device: DeviceOption = "cpu",
    fov: FovOption = None,
    focal: FocalOption = None,
    lens: LensOption = None,
    smooth: SmoothOption = 0.5,
    method: MethodOption = "adaptive",
    lock: LockOption = False,
    max_zoom: MaxZoomOption = 1.15,
    crop: CropOption = "auto",
    codec: CodecOption = "libx264",
    crf: CrfOption = 18,
    preset: PresetOption = "medium",
    report: Path | None = typer.Option(
        None, help="Write rotations.csv, path.csv, trajectory.png and summary.json here."
    ),
    preview: PreviewOption = "none",
    size: SizeOption = None,
    gyro: Path | None = typer.Option(
        None, help="Stabilise from this gyro log (synchronised to the video) instead."
    ),
    gyro_format: GyroFormatOption = None,
    gyro_offset: float | None = typer.Option(None, help="Gyro minus video clock, s."),
    gyro_axes: str | None = typer.Option(None, help="IMU axis of camera x, y, z, e.g. YXz."),
    gyro_lpf: GyroLpfOption = None,
    gyro_drift: GyroDriftOption = False,
    readout_ms: ReadoutOption = None,
    overwrite: OverwriteOption = False,
    quiet: QuietOption = False,
    as_json: JsonOption = False,
) -> None:
    """Stabilise a video: estimate each frame's rotation, smooth the path, warp, encode."""
    from stabilize.pipeline import stabilize_video
    from stabilize.progress import progress_bar
    from stabilize.video_reader import VideoError

    axes = None if gyro_axes is None else tuple(map(tuple, _axes(gyro_axes)))
    settings = _job_settings(**_shared(locals()), gyro_offset=gyro_offset, gyro_axes=axes)
    with contextlib.ExitStack() as stack:

        def bar(label: str, total: int | None):
            return stack.enter_context(progress_bar(label, total, quiet=quiet))

        try:
            summary, planned = stabilize_video(
                input_path, output_path, settings, overwrite=overwrite, progress=bar
            )
        except (VideoError, ValueError, FileExistsError, FileNotFoundError, RuntimeError) as err:
            _fail(str(err))
    if report is not None:
        from stabilize.report import write_report

        write_report(report, planned, summary)
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
    elif not quiet:
        typer.echo(
            f"{output_path}: {summary['frames']} frames, zoom {summary['zoom']:.3f}, "
            f"{summary['fps']:.1f} fps",
            err=True,
        )


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize rotations clip.mp4 -o rotations.csv\n\n"
        "  stabilize rotations clip.mp4 --gcsv clip.gcsv     # for Gyroflow\n\n"
        "  stabilize rotations clip.mp4 -o rot.csv --flow raft --raft-weights raft-small.pth"
    )
)
def rotations(
    input_path: Path = typer.Argument(..., metavar="IN", help="A video."),
    output: Path | None = typer.Option(
        None, "-o", "--output", help="CSV: frame,t,rx,ry,rz,support."
    ),
    gcsv: Path | None = typer.Option(
        None, help="Also (or only) write the rates as a Gyroflow .gcsv, for clips with no gyro."
    ),
    flow_name: FlowOption = "dis",
    raft_weights: RaftWeightsOption = None,
    device: DeviceOption = "cpu",
    fov: FovOption = None,
    focal: FocalOption = None,
    overwrite: OverwriteOption = False,
    quiet: QuietOption = False,
) -> None:
    """Estimate only: the camera rotation R_t of every frame pair (radians)."""
    from rotation import so3
    from stabilize.ffmpeg_tools import atomic_output
    from stabilize.pipeline import estimate_rotations
    from stabilize.progress import progress_bar
    from stabilize.rotation_files import write_rotations
    from stabilize.video_reader import VideoError, probe

    if output is None and gcsv is None:
        _fail("give -o rotations.csv and/or --gcsv out.gcsv")
    settings = _settings(flow_name, raft_weights, device, fov=fov, focal=focal)
    try:
        info = probe(input_path)
        with progress_bar("estimating", None, quiet=quiet) as advance:
            track = estimate_rotations(input_path, info, settings, advance)
        if output is not None:
            with atomic_output(output, overwrite=overwrite) as tmp:
                write_rotations(tmp, track.times[:-1], so3.log_so3(track.rotations), track.support)
        if gcsv is not None:
            from stabilize.gyro.export import write_gcsv

            with atomic_output(gcsv, overwrite=overwrite) as tmp:
                write_gcsv(tmp, track.times, track.rotations)
    except (VideoError, ValueError, FileExistsError, RuntimeError) as err:
        _fail(str(err))


def _output_size(text: str | None) -> tuple[int, int] | None:
    """--size WIDTHxHEIGHT → (H, W)."""
    if text is None:
        return None
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        _fail(f"--size must be WIDTHxHEIGHT, e.g. 1280x720, got {text!r}")
    if w < 16 or h < 16 or w > 16384 or h > 16384:
        _fail(f"--size {text}: each side must be 16..16384 pixels")
    return h, w


def _readout(value: str | None, gyro: object) -> float | str | None:
    """--readout-ms: a number of ms or 'auto'; rolling-shutter correction needs the gyro."""
    if value is not None and not gyro:
        _fail("--readout-ms corrects the rolling shutter from the gyro: give --gyro LOG too")
    if value is None or value == "auto":
        return value
    try:
        return float(value)
    except ValueError:
        _fail(f"--readout-ms takes a number of milliseconds or 'auto', got {value!r}")


def _axes(code: str | None):
    """'YXz' → R_cam_imu: camera x, y, z are IMU Y, X and -Z (lower case: negative)."""
    if code is None:
        return None
    if len(code) != 3 or sorted(code.upper()) != ["X", "Y", "Z"]:
        _fail(f"--axes must be three letters naming the IMU axis of camera x, y, z, got {code!r}")
    R = np.zeros((3, 3))
    for row, letter in enumerate(code):
        R[row, "XYZ".index(letter.upper())] = 1.0 if letter.isupper() else -1.0
    if np.linalg.det(R) < 0:
        _fail(f"--axes {code} is a reflection, not a rotation")
    return R


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize compare clip.mp4 --gyro gyro.csv --report cmp/\n\n"
        "  stabilize compare 'frames/RE_frame-%d.jpg' --start-number 99 --gyro gyro.txt "
        "--timestamps framestamp.txt --focal 573.85 --json\n\n"
        "  stabilize compare clip.mp4 --gyro log.gcsv --offset 0.042 --axes YXz\n\n"
        "  stabilize compare clip.mp4 --gyro gyro.csv --calibrate-focal --drift"
    )
)
def compare(
    video: str = typer.Argument(..., help="A video, or an image pattern like dir/img-%d.jpg."),
    gyro: Path = typer.Option(..., help="The gyro log."),
    gyro_format: GyroFormatOption = None,
    timestamps: Path | None = typer.Option(
        None, help="Frame times on the gyro clock (OpenCamera ns, or seconds per line)."
    ),
    start_number: int | None = typer.Option(None, help="First image number of a pattern."),
    fps: float | None = typer.Option(None, help="Frame rate of an image sequence."),
    fov: FovOption = None,
    focal: FocalOption = None,
    lens: LensOption = None,
    offset: float | None = typer.Option(None, help="Gyro minus video clock, s (skip the search)."),
    axes: str | None = typer.Option(None, help="IMU axis of camera x, y, z, e.g. YXz."),
    search: float = typer.Option(1.0, min=0.0, help="Offset search range, ± seconds."),
    readout_ms: str = typer.Option(
        "auto",
        help="Rolling-shutter readout, ms (0: global shutter), or 'auto': the log's value, "
        "else estimated from bands of the frame.",
    ),
    drift: bool = typer.Option(False, "--drift", help="Also fit a linear clock drift."),
    calibrate_focal: bool = typer.Option(
        False,
        "--calibrate-focal",
        help="Fit the focal length to the gyro (estimates the rotations again with it).",
    ),
    flow_name: FlowOption = "dis",
    raft_weights: RaftWeightsOption = None,
    report: Path | None = typer.Option(None, help="Write pairs.csv, summary.json and plots here."),
    as_json: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Compare the visual rotation estimate with a gyroscope log."""
    from stabilize import compare as cmp
    from stabilize.gyro import GyroError, read_gyro
    from stabilize.gyro.focal import focal_from_gyro
    from stabilize.gyro.readers import read_frame_timestamps_s
    from stabilize.gyro.sync import synchronise
    from stabilize.lens import read_lens_profile
    from stabilize.pipeline import READOUT_BANDS, estimate_rotations, readout_seconds
    from stabilize.progress import progress_bar
    from stabilize.video_reader import VideoError, frame_times, probe, sequence_args

    settings = _settings(flow_name, raft_weights, "cpu", fov=fov, focal=focal, max_deg=15.0)
    R_cam_imu = _axes(axes)
    try:
        log = read_gyro(gyro, gyro_format)
        args = sequence_args(video, start_number, fps)
        info = probe(video, args)
        times = frame_times(video, args)
        n = len(times)
        if timestamps is not None:
            stamps = read_frame_timestamps_s(timestamps)
            if stamps[0] > 1e12:  # integer nanoseconds (OpenCamera), not seconds
                stamps = stamps * 1e-9
            first = (start_number or 1) - 1 if args else 0  # line N is image N
            times = stamps[first : first + n]
            if len(times) < n:
                _fail(f"{timestamps}: {len(stamps)} frame times, the video needs {first + n}")
        camera = read_lens_profile(lens, info.size) if lens else None
        if camera is not None and calibrate_focal:
            _fail("--calibrate-focal fits a pinhole focal length; --lens brings its own")
        if camera is not None:
            settings = replace(settings, focal=float(camera.K[0, 0]))
        # Unlike the stabiliser, compare estimates (None) a readout the log does not give.
        parsed = _readout(readout_ms, gyro)
        given = log.readout_s or (camera and camera.readout_s)
        readout = given if parsed == "auto" else readout_seconds(parsed, None)
        bands = READOUT_BANDS if readout is None else 0

        def estimate_and_sync(settings):
            with progress_bar("estimating", n - 1, quiet=quiet) as advance:
                track = estimate_rotations(
                    video, info, settings, advance, times, bands=bands, lens=camera
                )
            sync = synchronise(
                log,
                track,
                search=(-search, search),
                offset=offset,
                R_cam_imu=R_cam_imu,
                readout=readout,
                fit_drift=drift,
            )
            return track, sync

        track, sync = estimate_and_sync(settings)
        for _ in range(FOCAL_ROUNDS if calibrate_focal else 0):
            old = settings.focal_px(info.width)
            fitted = focal_from_gyro(track, log, sync, old)
            settings = replace(settings, focal=fitted)
            track, sync = estimate_and_sync(settings)
            if abs(fitted / old - 1.0) < 0.005:
                break
        result = cmp.compare(track, log, sync, settings.focal_px(info.width))
    except (VideoError, GyroError, ValueError) as err:
        _fail(str(err))
    summary = result.summary() | {"focal_calibrated": calibrate_focal}
    if report is not None:
        cmp.write_report(report, result)
    if summary["warning"]:
        typer.secho(f"WARNING: {summary['warning']}", err=True, fg="red", bold=True)
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
        return
    estimated = " (estimated)" if summary["readout_estimated"] else ""
    typer.echo(
        f"{summary['frames']} pairs: AAE {summary['aae_deg']:.4f}°, median "
        f"{summary['median_deg']:.4f}°, p95 {summary['p95_deg']:.4f}° (pitch "
        f"{summary['aae_pitch_deg']:.4f}°, yaw {summary['aae_yaw_deg']:.4f}°, roll "
        f"{summary['aae_roll_deg']:.4f}°)\noffset {1000 * summary['offset_s']:+.2f} ms, readout "
        f"{summary['readout_ms']:.1f} ms{estimated}, gyro "
        f"{summary['gyro_rate_hz']:.1f} Hz, focal {summary['focal_px']:.1f} px, speed "
        f"correlation {summary['speed_correlation']:.3f}\nR_cam_imu = "
        f"{np.round(np.array(summary['R_cam_imu']), 4).tolist()}"
    )


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize batch trip/ trip-steady/\n\n"
        "  stabilize batch phone/ out/ --recursive --pattern '*.mp4' --workers 2\n\n"
        "  stabilize batch clips/ out/ --gyro auto   # clip.gcsv or clip.csv beside clip.mp4\n\n"
        "  stabilize batch /shared/in /shared/out --ray auto"
    )
)
def batch(
    in_dir: Path = typer.Argument(..., help="Folder of clips."),
    out_dir: Path = typer.Argument(..., help="Where the stabilised clips go (same tree)."),
    workers: int | None = typer.Option(None, min=1, help="Parallel files (default: per core)."),
    pattern: str = typer.Option("*", help="Which files, as a glob."),
    recursive: bool = typer.Option(False, help="Descend into subfolders."),
    gyro: str | None = typer.Option(None, help="'auto': use a gyro log with the same base name."),
    ray: str | None = typer.Option(
        None, help="Run on a Ray cluster: its address, or 'auto' (needs the 'cluster' extra)."
    ),
    flow_name: FlowOption = "dis",
    raft_weights: RaftWeightsOption = None,
    device: DeviceOption = "cpu",
    fov: FovOption = None,
    focal: FocalOption = None,
    lens: LensOption = None,
    smooth: SmoothOption = 0.5,
    method: MethodOption = "adaptive",
    lock: LockOption = False,
    max_zoom: MaxZoomOption = 1.15,
    crop: CropOption = "auto",
    codec: CodecOption = "libx264",
    crf: CrfOption = 18,
    preset: PresetOption = "medium",
    preview: PreviewOption = "none",
    size: SizeOption = None,
    gyro_format: GyroFormatOption = None,
    gyro_lpf: GyroLpfOption = None,
    gyro_drift: GyroDriftOption = False,
    readout_ms: ReadoutOption = None,
    quiet: QuietOption = False,
) -> None:
    """Stabilise every clip in a folder: resumable, one failure never stops the rest."""
    from rich.console import Console
    from rich.table import Table

    from stabilize.batch import find_jobs, run_batch
    from stabilize.progress import batch_progress

    if not in_dir.is_dir():
        _fail(f"{in_dir}: not a folder")
    if gyro not in (None, "auto"):
        _fail("--gyro in batch mode takes 'auto' (a sidecar log per clip)")
    settings = _job_settings(**_shared(locals()))
    jobs = find_jobs(in_dir, out_dir, pattern, recursive, gyro_auto=gyro == "auto")
    if not jobs:
        _fail(f"{in_dir}: no files match {pattern!r}")
    console = Console(stderr=True)
    with batch_progress(len(jobs), quiet=quiet) as (file_done, frames_done):

        def done(row: dict) -> None:
            file_done()
            if not quiet:
                console.print(f"{row['status']:8s} {row['input']}  {row.get('error', '')}")

        try:
            rows = run_batch(
                jobs, out_dir, settings, workers, done, ray_address=ray, on_frames=frames_done
            )
        except (RuntimeError, ConnectionError) as err:
            _fail(str(err).splitlines()[0])
    table = Table(title=f"{len(rows)} files → {out_dir}")
    for column in ("input", "status", "seconds", "zoom", "error"):
        table.add_column(column)
    for row in rows:
        zoom = f"{row['zoom']:.3f}" if row.get("zoom") else ""
        table.add_row(
            row["input"], row["status"], f"{row.get('seconds', 0):.1f}", zoom, row.get("error", "")
        )
    if not quiet:
        console.print(table)
    failed = sum(row["status"] == "failed" for row in rows)
    if failed:
        typer.echo(
            f"{failed} of {len(rows)} files failed (see {out_dir / 'manifest.json'})", err=True
        )
        raise typer.Exit(1)


COMMANDS = ("run", "rotations", "synth", "evaluate", "compare", "batch")


def main() -> None:
    """Console-script entry point: a first argument that is no command runs the main job."""
    args = sys.argv[1:]
    if args and not args[0].startswith("-") and args[0] not in COMMANDS:
        args = ["run", *args]
    app(args=args, prog_name="stabilize")


if __name__ == "__main__":
    main()
