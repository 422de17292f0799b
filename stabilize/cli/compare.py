"""``stabilize compare VIDEO --gyro LOG``: the visual estimate against a gyroscope."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import typer
from numpy.typing import NDArray

from stabilize.cli.app import announce_compiling, app, notice, run_or_fail
from stabilize.cli.bars import with_bars
from stabilize.cli.options import (
    GYRO_SEARCH,
    SIDECARS,
    FlowOption,
    FocalOption,
    FovOption,
    FpsOption,
    GyroAxesOption,
    GyroDriftOption,
    GyroFormatOption,
    GyroOffsetOption,
    GyroSearchOption,
    GyroTimestampsOption,
    JsonOption,
    LensOption,
    QuietOption,
    RaftWeightsOption,
    axes_matrix,
    field_of_view,
    flow_settings,
    readout,
)
from stabilize.progress import ProgressFactory
from stabilize.settings import DEFAULTS, LENS_WITH_FOCAL
from stabilize.video.probe import VideoInfo


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize compare clip.mp4 --gyro gyro.csv --report cmp/\n\n"
        "  stabilize compare 'frames/RE_frame-%d.jpg' --gyro gyro.txt "
        "--gyro-timestamps framestamp.txt --focal 573.85 --json\n\n"
        "  stabilize compare clip.mp4 --gyro log.gcsv --gyro-offset 0.042 --gyro-axes YXz\n\n"
        "  stabilize compare clip.mp4 --gyro gyro.csv --calibrate-focal --gyro-drift"
    )
)
def compare(
    ctx: typer.Context,
    video: str = typer.Argument(..., help="A video, or an image pattern like dir/img-%d.jpg."),
    gyro: Path = typer.Option(
        ...,
        help=f"The gyro log; 'auto': the one beside the clip, of its name ({SIDECARS}), else "
        "the one its camera recorded in it (a GoPro's).",
    ),
    gyro_format: GyroFormatOption = None,
    gyro_timestamps: GyroTimestampsOption = None,
    start_number: int | None = typer.Option(
        None, help="First image number of a pattern (default: the lowest its files carry)."
    ),
    fps: FpsOption = None,
    fov: FovOption = DEFAULTS.fov,
    focal: FocalOption = DEFAULTS.focal,
    lens: LensOption = None,
    gyro_offset: GyroOffsetOption = None,
    gyro_axes: GyroAxesOption = None,
    gyro_search: GyroSearchOption = GYRO_SEARCH,
    readout_ms: str = typer.Option(
        "auto",
        help="Rolling-shutter readout, ms (0: global shutter), or 'auto': the log's value, "
        "else estimated from bands of the frame.",
    ),
    gyro_drift: GyroDriftOption = DEFAULTS.gyro_drift,
    calibrate_focal: bool = typer.Option(
        False,
        "--calibrate-focal",
        help="Fit the focal length to the gyro (estimates the rotations again with it).",
    ),
    flow_name: FlowOption = DEFAULTS.flow,
    raft_weights: RaftWeightsOption = None,
    report: Path | None = typer.Option(None, help="Write pairs.csv, summary.json and plots here."),
    as_json: JsonOption = False,
    quiet: QuietOption = False,
    # The spellings before run and compare shared one vocabulary, kept working:
    timestamps: Path | None = typer.Option(None, "--timestamps", hidden=True),
    offset: float | None = typer.Option(None, "--offset", hidden=True),
    axes: str | None = typer.Option(None, "--axes", hidden=True),
    search: float | None = typer.Option(None, "--search", min=0.0, hidden=True),
    drift: bool = typer.Option(False, "--drift", hidden=True),
) -> None:
    """Compare the visual rotation estimate with a gyroscope log."""
    params = _canonical(ctx.params)
    result = run_or_fail(lambda: with_bars(lambda bar: _comparison(params, bar), quiet=quiet))
    summary = result.summary() | {"focal_calibrated": calibrate_focal}
    if report is not None:
        from stabilize.evaluate.compare import write_comparison

        write_comparison(report, result)
    if summary["warning"]:
        typer.secho(f"WARNING: {summary['warning']}", err=True, fg="red", bold=True)
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
        return
    typer.echo(_describe(summary))


ALIASES = {  # an old spelling → the option it stands for
    "timestamps": "gyro_timestamps",
    "offset": "gyro_offset",
    "axes": "gyro_axes",
    "search": "gyro_search",
    "drift": "gyro_drift",
}


def _canonical(params: dict) -> dict:
    """The options under their names, an old spelling standing in where it was used."""
    out = {k: v for k, v in params.items() if k not in ALIASES}
    for old, name in ALIASES.items():
        if params[old] not in (None, False):
            out[name] = params[old]
    return out


def _comparison(params: dict, bar: ProgressFactory):
    """The comparison the parsed options ``params`` ask for."""
    from stabilize.evaluate.compare import compare_video
    from stabilize.gyro import read_gyro
    from stabilize.gyro.load import AUTO_FOR_SEQUENCE, gyro_log_for, starting_readout
    from stabilize.gyro.sync import SyncOptions
    from stabilize.video.sequence import is_pattern
    from stabilize.warp.lens import read_lens_profile

    flow_name, weights, fov, focal = (
        params[k] for k in ("flow_name", "raft_weights", "fov", "focal")
    )
    settings = flow_settings(
        flow_name, weights, "cpu", fov=field_of_view(fov), focal=focal, max_deg=15.0
    )
    if params["lens"] and settings.fov_given:
        raise ValueError(LENS_WITH_FOCAL)
    R_cam_imu = axes_matrix(params["gyro_axes"])
    calibrate = params["calibrate_focal"]
    gyro, video = params["gyro"], params["video"]
    auto = str(gyro) == "auto"  # found beside the video, once it is known to be one
    if auto and is_pattern(video):
        raise ValueError(AUTO_FOR_SEQUENCE)
    log = None if auto else read_gyro(gyro, params["gyro_format"])
    info, times = _video_and_times(
        video, params["start_number"], params["fps"], params["gyro_timestamps"]
    )
    log = log or read_gyro(gyro_log_for(video), params["gyro_format"])
    camera = read_lens_profile(params["lens"], info.size) if params["lens"] else None
    if camera is not None and calibrate:
        raise ValueError("--calibrate-focal fits a pinhole focal length; --lens brings its own")
    if camera is not None:
        settings = replace(settings, focal=float(camera.K[0, 0]))
    # compare's 'auto' (its default) is the stabiliser's default: the log's, else the
    # lens profile's, else estimated
    parsed = readout(params["readout_ms"], params["gyro"])
    option = None if parsed == "auto" else parsed
    known, source = starting_readout(option, log.readout_s, camera and camera.readout_s)
    options = SyncOptions(
        params["gyro_offset"], R_cam_imu, known, params["gyro_drift"], params["gyro_search"], source
    )
    announce_compiling()
    return compare_video(
        params["video"],
        info,
        log,
        settings,
        times,
        options,
        lens=camera,
        calibrate_focal=calibrate,
        progress=bar,
    )


def _video_and_times(
    video: str, start_number: int | None, fps: float | None, timestamps: Path | None
) -> tuple[VideoInfo, NDArray]:
    """The video (or image sequence) and its frame times: the container's, or those of a
    ``timestamps`` file on the sensor's clock (line N is image N of a sequence)."""
    from stabilize.video import frame_times, probe, sequence_args
    from stabilize.video.sequence import rate_notice

    args = sequence_args(video, start_number, fps)
    info = probe(video, args).stored()  # the sensor's rows and axes, however it was held
    for said in rate_notice(video, fps) if timestamps is None else ():  # the sync's clock
        notice(said)
    times = frame_times(video, args)
    if timestamps is not None:
        from stabilize.gyro.readers import first_stamp, sensor_frame_times
        from stabilize.video.sequence import first_image

        first = first_stamp(first_image(info.input_args))
        times = sensor_frame_times(timestamps, first, len(times))
    return info, times


# where the readout came from, in the description's words (given: nothing to add)
READOUT_WORDS = {
    "estimated": " (estimated)",
    "none": " (not pinned down by the bands: taken as a global shutter)",
    "log": " (the log's)",
    "lens": " (the lens profile's)",
}


def _describe(summary: dict) -> str:
    """The comparison in three lines of text."""
    source = READOUT_WORDS.get(summary["readout_source"], "")
    if summary["readout_source"] == "estimated" and not summary["readout_ms"]:
        source = " (estimated: a global shutter)"
    return (
        f"{summary['frames']} pairs: AAE {summary['aae_deg']:.4f}°, median "
        f"{summary['median_deg']:.4f}°, p95 {summary['p95_deg']:.4f}° (pitch "
        f"{summary['aae_pitch_deg']:.4f}°, yaw {summary['aae_yaw_deg']:.4f}°, roll "
        f"{summary['aae_roll_deg']:.4f}°)\noffset {1000 * summary['offset_s']:+.2f} ms, readout "
        f"{summary['readout_ms']:.1f} ms{source}, gyro "
        f"{summary['gyro_rate_hz']:.1f} Hz, focal {summary['focal_px']:.1f} px, speed "
        f"correlation {summary['speed_correlation']:.3f}\nR_cam_imu = "
        f"{np.round(np.array(summary['R_cam_imu']), 4).tolist()}"
    )
