"""``stabilize rotations``: estimation only, each frame pair's rotation R_t."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from stabilize.cli.app import announce_compiling, app, fail, notice, run_or_fail
from stabilize.cli.options import (
    DeviceOption,
    FlowOption,
    FocalOption,
    FovOption,
    FpsOption,
    LensOption,
    OverwriteOption,
    QuietOption,
    RaftWeightsOption,
    field_of_view,
    flow_settings,
)
from stabilize.settings import DEFAULTS, LENS_WITH_FOCAL

STDOUT = Path("-")  # the Unix name of standard output, where a file is asked for


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize rotations clip.mp4 -o rotations.csv\n\n"
        "  stabilize rotations clip.mp4 --gcsv clip.gcsv     # for Gyroflow\n\n"
        "  stabilize rotations clip.mp4 -o - | head\n\n"
        "  stabilize rotations clip.mp4 -o rot.csv --flow raft --raft-weights raft-small.pth"
    )
)
def rotations(
    input_path: Path = typer.Argument(
        ..., metavar="IN", help="A video, or an image sequence (frames/img-%d.jpg)."
    ),
    output: Path | None = typer.Option(
        None, "-o", "--output", help="CSV: frame,t,rx,ry,rz,support ('-': standard output)."
    ),
    gcsv: Path | None = typer.Option(
        None,
        help="Also (or only) write the rates as a Gyroflow .gcsv, for clips with no gyro "
        "('-': standard output): the turns the stabiliser follows, a cut's and an "
        "unreliable pair's taken from the pairs beside it.",
    ),
    flow_name: FlowOption = DEFAULTS.flow,
    raft_weights: RaftWeightsOption = None,
    device: DeviceOption = DEFAULTS.device,
    fov: FovOption = DEFAULTS.fov,
    focal: FocalOption = DEFAULTS.focal,
    lens: LensOption = None,
    fps: FpsOption = None,
    overwrite: OverwriteOption = False,
    quiet: QuietOption = False,
) -> None:
    """Estimate only: the camera rotation R_t of every frame pair (radians), in the
    camera's axes as its sensor stores the frames (a clip shown turned, as a phone held
    upright records, is read unturned)."""
    from rotation import so3
    from stabilize.cli.bars import with_bars
    from stabilize.motion.cuts import said_cuts, track_breaks
    from stabilize.motion.estimate import Damaged
    from stabilize.motion.files import write_rotations
    from stabilize.motion.focal import estimate_motion
    from stabilize.video import atomic_output, probe, sequence_args
    from stabilize.video.atomic import check_absent, check_not_input
    from stabilize.video.preflight import check_writable
    from stabilize.video.sequence import rate_notice
    from stabilize.warp.lens import read_lens_profile

    if output is None and gcsv is None:
        fail("give -o rotations.csv and/or --gcsv out.gcsv")
    targets = [t for t in (output, gcsv) if t is not None]
    if len(targets) == 2 and output.resolve() == gcsv.resolve():
        fail(f"-o and --gcsv both name {output}: give each its own file")
    for target in targets:  # before any work, not after it
        if target == STDOUT:
            continue
        run_or_fail(lambda target=target: check_not_input(target, input_path))
        run_or_fail(lambda target=target: check_absent(target, overwrite))
        run_or_fail(lambda target=target: check_writable(target))
    settings = flow_settings(flow_name, raft_weights, device, fov=field_of_view(fov), focal=focal)
    if lens and settings.fov_given:
        fail(LENS_WITH_FOCAL)
    # the sensor's axes, as compare's
    info = run_or_fail(lambda: probe(input_path, sequence_args(input_path, fps=fps)).stored())
    for said in rate_notice(input_path, fps):  # the CSV's and the .gcsv's times
        notice(said)
    # the flow is read through the lens: a fisheye's rotations taken as a pinhole's were
    # 0.015° a pair further from the truth (tests/stabilize/warp/test_lens.py)
    camera = run_or_fail(lambda: read_lens_profile(lens, info.size)) if lens else None

    # the flow vectors: the .gcsv's repair checks each jump against them, and an edited
    # clip's shots are voted again at their own focal lengths from them (where the focal
    # length is estimated: neither given nor a lens's)
    keep = gcsv is not None or (camera is None and not settings.fov_given)

    def estimate(bar):
        try:
            return estimate_motion(
                input_path, info, settings, bar("estimating", None), lens=camera, keep_samples=keep
            )
        except Damaged as damage:  # the frames that decode, each at its own time
            times = damage.frames_that_decode(info)
            notice(damage.notice)
            return estimate_motion(
                input_path,
                info,
                settings,
                bar("estimating", None),
                times,
                lens=camera,
                keep_samples=keep,
            )

    announce_compiling()
    track, focal = run_or_fail(lambda: with_bars(estimate, quiet=quiet))
    across = f"{focal.fov_deg:.1f}° across the long side"
    notice(f"focal length {focal.px:.1f} px ({across}, {focal.source})")
    if focal.shots:  # a montage of two cameras
        notice(f"focal length: {focal.said_shots(track.times)}")
    breaks = track_breaks(track)
    cuts = breaks.cuts
    if cuts.any():  # their rows are no camera's turn
        notice(f"{said_cuts(track.times[1:][cuts])}: marked in the rotations' cut column")

    def write(target: Path, writer) -> None:
        """``writer`` into standard output (``-``), else into ``target`` atomically."""
        if target == STDOUT:
            writer(sys.stdout)
            return
        with atomic_output(target, overwrite=overwrite) as tmp:
            writer(tmp)

    if output is not None:
        rotvecs = so3.log_so3(track.rotations)
        rows = (track.times[:-1], rotvecs, track.support, cuts)
        write(output, lambda to: write_rotations(to, *rows))
    if gcsv is not None:
        from stabilize.gyro.export import write_gcsv
        from stabilize.motion.repair import repair_track

        # Gyroflow integrates every rate it is given: a cut's row, read as a turn, would
        # turn the whole shot after it (5.6 degrees at a second of hero7 cut to karma, 70°)
        R, reliable = repair_track(track, focal.px, breaks.unrelated)
        if not reliable.all():
            notice(
                f"{int((~reliable).sum())} of {len(reliable)} pairs' turns in the .gcsv are "
                "taken from the pairs beside them (cuts, interruptions, and pairs too few "
                "vectors agreed on)"
            )
        write(gcsv, lambda to: write_gcsv(to, track.times, R))
