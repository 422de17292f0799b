"""``stabilize run IN OUT`` (or just ``stabilize IN OUT``): the main job."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import typer

from stabilize.cli.app import app, check_report_folder, fail, notice, run_or_fail
from stabilize.cli.options import (
    ENCODING,
    GYRO_SEARCH,
    NO_PREVIEW,
    SIDECARS,
    BarsOption,
    BorderOption,
    CodecOption,
    CrfOption,
    CropOption,
    DeinterlaceOption,
    DeviceOption,
    FlowOption,
    FocalOption,
    FovOption,
    FpsOption,
    GyroAxesOption,
    GyroDriftOption,
    GyroFormatOption,
    GyroLpfOption,
    GyroOffsetOption,
    GyroSearchOption,
    GyroTimestampsOption,
    JsonOption,
    LensOption,
    LockOption,
    MaxStretchOption,
    MaxZoomOption,
    MethodOption,
    MotionOption,
    OverwriteOption,
    PixFmtOption,
    PresetOption,
    PreviewOption,
    QuietOption,
    RaftWeightsOption,
    ReadoutOption,
    RollingShutterOption,
    SizeOption,
    SmoothOption,
    job_settings,
)
from stabilize.settings import DEFAULTS

AUTO_GYRO = Path("auto")


def gyro_beside_or_in(clip: Path) -> dict:
    """The Settings fields of ``--gyro auto`` for ``clip``: the log beside it, else its
    camera's own, which gives way to the video where it does not match it; or an error."""
    from stabilize.gyro.load import AUTO_FOR_SEQUENCE, gyro_log_for, gyro_settings
    from stabilize.video.sequence import is_pattern

    if is_pattern(clip):
        fail(AUTO_FOR_SEQUENCE)
    if not clip.is_file():
        return {}  # said by the job: no such file, a folder
    return gyro_settings(run_or_fail(lambda: gyro_log_for(clip)), clip)


@app.command(
    "run",
    epilog=(
        "The main job; `stabilize IN OUT` is short for `stabilize run IN OUT`.\n\n"
        "Examples:\n\n"
        "  stabilize shaky.mp4 steady.mp4\n\n"
        "  stabilize shaky.mp4 steady.mp4 --smooth 1.0 --max-zoom 1.3 --report report/\n\n"
        "  stabilize drone.mp4 locked.mp4 --lock --crop dynamic\n\n"
        "  stabilize 'frames/img-%05d.jpg' steady.mp4 --fps 30\n\n"
        "  stabilize shaky.mp4 'steady/%05d.png'     # a picture per frame\n\n"
        "  stabilize gopro.mp4 out.mp4 --lens 'GoPro_HERO7 Black_Wide_16by9.json'\n\n"
        "  stabilize in.mp4 out.mp4 --flow raft --raft-weights raft-small.pth --device cuda"
    ),
)
def run(
    ctx: typer.Context,
    input_path: Path = typer.Argument(
        ..., metavar="IN", help="The shaky video, or an image sequence (frames/img-%d.jpg)."
    ),
    output_path: Path = typer.Argument(
        ...,
        metavar="OUT",
        help="Where to write the result: a video, a GIF, or pictures (f/%05d.png).",
    ),
    flow_name: FlowOption = DEFAULTS.flow,
    raft_weights: RaftWeightsOption = None,
    device: DeviceOption = DEFAULTS.device,
    fov: FovOption = DEFAULTS.fov,
    focal: FocalOption = DEFAULTS.focal,
    lens: LensOption = None,
    smooth: SmoothOption = DEFAULTS.smooth,
    method: MethodOption = DEFAULTS.method,
    motion: MotionOption = DEFAULTS.motion,
    lock: LockOption = False,
    max_zoom: MaxZoomOption = DEFAULTS.max_zoom,
    crop: CropOption = DEFAULTS.crop,
    border: BorderOption = DEFAULTS.border,
    codec: CodecOption = ENCODING.codec,
    crf: CrfOption = ENCODING.crf,
    preset: PresetOption = ENCODING.preset,
    pix_fmt: PixFmtOption = ENCODING.pix_fmt,
    report: Path | None = typer.Option(
        None, help="Write rotations.csv, path.csv, trajectory.png and summary.json here."
    ),
    preview: PreviewOption = NO_PREVIEW,
    size: SizeOption = None,
    deinterlace: DeinterlaceOption = DEFAULTS.deinterlace,
    bars: BarsOption = DEFAULTS.bars,
    fps: FpsOption = None,
    gyro: Path | None = typer.Option(
        None,
        help="Stabilise from this gyro log (synchronised to the video) instead; 'auto': "
        f"the one beside the clip, of its name ({SIDECARS}), else the one its camera "
        "recorded in it (a GoPro's), unless that does not match its video (a clip "
        "stabilised in the camera: then its video's motion, with a notice).",
    ),
    gyro_format: GyroFormatOption = None,
    gyro_offset: GyroOffsetOption = None,
    gyro_axes: GyroAxesOption = None,
    gyro_timestamps: GyroTimestampsOption = None,
    gyro_search: GyroSearchOption = GYRO_SEARCH,
    gyro_lpf: GyroLpfOption = DEFAULTS.gyro_lpf,
    gyro_drift: GyroDriftOption = DEFAULTS.gyro_drift,
    readout_ms: ReadoutOption = None,
    rolling_shutter: RollingShutterOption = str(DEFAULTS.rolling_shutter),
    max_stretch: MaxStretchOption = DEFAULTS.max_stretch,
    overwrite: OverwriteOption = False,
    quiet: QuietOption = False,
    as_json: JsonOption = False,
) -> None:
    """Stabilise a video: estimate each frame's rotation, smooth the path, warp, encode."""
    settings = job_settings(ctx.params)  # first: an option's mistake costs no import
    if gyro == AUTO_GYRO:
        settings = replace(settings, **gyro_beside_or_in(input_path))
    if report is not None:
        check_report_folder(report)
    from stabilize.cli.bars import with_bars
    from stabilize.pipeline import stabilize_video

    def job(bar):
        return stabilize_video(
            input_path, output_path, settings, overwrite=overwrite, progress=bar, notify=notice
        )

    summary, planned = run_or_fail(lambda: with_bars(job, quiet=quiet))
    if report is not None:
        from stabilize.evaluate.report import write_report

        run_or_fail(lambda: write_report(report, planned, summary))
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
    elif not quiet:
        typer.echo(
            # the work's speed, in words a clip's frame rate is not read for ("46.9 fps")
            f"{output_path}: {summary['frames']} frames, zoom {summary['zoom']:.3f} "
            f"(cropping ratio {summary['cropping_ratio']:.3f}), "
            f"in {summary['seconds']['total']:.1f} s ({summary['fps']:.1f} frames a second)",
            err=True,
        )
