"""``stabilize batch IN_DIR OUT_DIR``: a folder of clips, resumable, locally or on Ray."""

from __future__ import annotations

from pathlib import Path

import typer

from stabilize.cli.app import announce_compiling, app, fail, notice, run_or_fail
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
    GyroDriftOption,
    GyroFormatOption,
    GyroLpfOption,
    GyroSearchOption,
    LensOption,
    LockOption,
    MaxStretchOption,
    MaxZoomOption,
    MethodOption,
    MotionOption,
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
    ctx: typer.Context,
    in_dir: Path = typer.Argument(..., help="Folder of clips."),
    out_dir: Path = typer.Argument(..., help="Where the stabilised clips go (same tree)."),
    workers: int | None = typer.Option(None, min=1, help="Parallel files (default: per core)."),
    pattern: str | None = typer.Option(
        None,
        help="Which files, as a glob (default: every file named as a video: .mp4, .mov, "
        ".mkv, .mts, … in any case; not a camera's proxies, .LRV).",
    ),
    recursive: bool = typer.Option(False, help="Descend into subfolders."),
    gyro: str | None = typer.Option(
        None,
        help=f"'auto': use the gyro log beside each clip, of the same name ({SIDECARS}), "
        "else the one its camera recorded in it (a GoPro's), unless that does not match its "
        "video (a clip stabilised in the camera: then its video's motion, with a notice).",
    ),
    output_format: str | None = typer.Option(
        None,
        "--format",
        help="Write every clip as this container, e.g. .mkv (default: each input's).",
    ),
    force: bool = typer.Option(
        False,
        "--force",
        help="Redo every file, finished or not, and replace files at the outputs' names "
        "that no batch wrote.",
    ),
    ray: str | None = typer.Option(
        None, help="Run on a Ray cluster: its address, or 'auto' (needs the 'cluster' extra)."
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
    preview: PreviewOption = NO_PREVIEW,
    size: SizeOption = None,
    deinterlace: DeinterlaceOption = DEFAULTS.deinterlace,
    bars: BarsOption = DEFAULTS.bars,
    gyro_format: GyroFormatOption = None,
    gyro_search: GyroSearchOption = GYRO_SEARCH,
    gyro_lpf: GyroLpfOption = DEFAULTS.gyro_lpf,
    gyro_drift: GyroDriftOption = DEFAULTS.gyro_drift,
    readout_ms: ReadoutOption = None,
    rolling_shutter: RollingShutterOption = str(DEFAULTS.rolling_shutter),
    max_stretch: MaxStretchOption = DEFAULTS.max_stretch,
    quiet: QuietOption = False,
) -> None:
    """Stabilise every clip in a folder: resumable, one failure never stops the rest."""
    from rich.console import Console

    import flow
    from stabilize.batch import BYTES_PER_WORKER, default_workers, run_batch
    from stabilize.cli.bars import batch_progress
    from stabilize.pipeline import check_settings
    from stabilize.warp.lens import read_lens_profile

    if not in_dir.is_dir():
        fail(f"{in_dir}: not a folder")
    if gyro not in (None, "auto"):
        fail("--gyro in batch mode takes 'auto' (a sidecar log per clip)")
    settings = job_settings(ctx.params)
    # once, before the files: each failed alike with the same message
    run_or_fail(lambda: check_settings(settings))
    if lens is not None:  # whether it can be read; whether it fits a clip is that clip's
        run_or_fail(lambda: read_lens_profile(lens))
    run_or_fail(lambda: flow.check_weights(flow_name, raft_weights))
    jobs = _jobs(ctx.params, settings)
    most = default_workers()
    if workers and not ray and min(workers, len(jobs)) > most:
        notice(
            f"--workers {workers}: this machine runs {most} at once (a core each, "
            f"and {BYTES_PER_WORKER / 2**30:.1f} GB of memory for a 1080p clip); more take as "
            "long or longer, and may be killed for memory"
        )
    announce_compiling()
    console = Console(stderr=True)
    with batch_progress(len(jobs), quiet=quiet) as (file_done, frames_done):

        def done(row: dict) -> None:
            file_done()
            if not quiet:
                console.print(f"{row['status']:8s} {row['input']}  {row.get('error', '')}")
                for said in row.get("notices", ()):
                    console.print(f"         notice: {said}", markup=False, highlight=False)

        try:
            rows = run_batch(jobs, out_dir, settings, workers, done, ray, frames_done, force=force)
        except (RuntimeError, ConnectionError) as err:
            fail(str(err).splitlines()[0])
    _print_rows(rows, out_dir, quiet)


def _jobs(params: dict, settings) -> list:
    """The folder's jobs, after checking that their outputs' containers (``--format``'s, or
    each input's) take the encoder, and that it writes the pixel format asked for."""
    from stabilize.batch import find_jobs
    from stabilize.video.containers import container_for
    from stabilize.video.preflight import check_encoder, check_pix_fmt

    fmt, pattern = params["output_format"], params["pattern"]
    suffix = (fmt if fmt.startswith(".") else f".{fmt}") if fmt else None
    if suffix:
        # named as the outputs are (OUT_DIR/*.mkv): its message named a file 'check.xyz'
        every = Path(params["out_dir"]) / f"*{suffix}"
        run_or_fail(lambda: check_encoder(every, settings.encoding, (64, 64)))
    gyro_auto = params["gyro"] == "auto"
    in_dir, out_dir = params["in_dir"], params["out_dir"]
    inside = Path(in_dir).resolve()
    if Path(out_dir).resolve() in (inside, *inside.parents):
        # every clip under the output folder is taken for an output and skipped: this
        # read "no files match" before
        fail(f"{out_dir}: the output folder holds the input folder {in_dir}: choose one outside it")
    jobs = run_or_fail(
        lambda: find_jobs(in_dir, out_dir, pattern, params["recursive"], gyro_auto, suffix, notice)
    )
    if not jobs:
        fail(f"{in_dir}: no files match {pattern!r}" if pattern else f"{in_dir}: no videos")
    asked = settings.encoding
    if asked.codec or asked.pix_fmt:
        # each container the outputs are in, as their inputs' suffixes name them: a codec
        # FFmpeg does not have, or one a container does not take, failed every such clip
        # in turn, the batch ending in a table of failures
        for kind in sorted({Path(job.output).suffix.lower() for job in jobs}):
            every = Path(out_dir) / f"*{kind}"
            written = asked.for_frames(container_for(every), "yuv420p")
            run_or_fail(lambda written=written: check_pix_fmt(written))
            if not suffix:  # (--format's was checked above)
                run_or_fail(lambda every=every: check_encoder(every, asked, (64, 64)))
    return jobs


def _print_rows(rows: list[dict], out_dir: Path, quiet: bool) -> None:
    """The batch's table of files, and exit status 1 if any failed."""
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{len(rows)} files → {out_dir}")
    for column in ("input", "status", "seconds", "zoom", "error"):
        table.add_column(column)
    for row in rows:
        zoom = f"{row['zoom']:.3f}" if row.get("zoom") else ""
        table.add_row(
            row["input"], row["status"], f"{row.get('seconds', 0):.1f}", zoom, row.get("error", "")
        )
    if not quiet:
        Console(stderr=True).print(table)
    failed = sum(row["status"] == "failed" for row in rows)
    if failed:
        typer.echo(
            f"{failed} of {len(rows)} files failed (see {out_dir / 'manifest.json'})", err=True
        )
        raise typer.Exit(1)
