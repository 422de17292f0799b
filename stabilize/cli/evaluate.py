"""``stabilize evaluate``: the quality metrics of a stabilised clip and its original."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import typer

from stabilize.cli.app import app, fail, run_or_fail
from stabilize.cli.bars import progress_bar
from stabilize.cli.options import FpsOption, QuietOption


@app.command(
    epilog=(
        "Examples:\n\n"
        "  stabilize evaluate shaky.mp4 steady.mp4\n\n"
        "  stabilize evaluate shaky.mp4 vidstab.mp4 --json > metrics.json\n\n"
        "  stabilize evaluate shaky.mp4 steady.mp4 --plot shake.png\n\n"
        "  stabilize evaluate shaky.mp4 steady.mp4 --spread\n\n"
        "  stabilize evaluate shaky.mp4 steady.mp4 --spread --sizes\n\n"
        "  stabilize evaluate clip.mp4 out.mp4 --truth truth.csv --rotations rotations.csv\n\n"
        "Residual shake: consecutive frames are registered by a similarity (ORB matches "
        "refined to a fraction of a pixel by Lucas-Kanade, RANSAC); "
        "each frame-to-frame motion (dx, dy, and the rotation and zoom as the px they move "
        "the frame's side, at the clip's width) is high-passed (minus a Gaussian low-pass, "
        "sigma 0.5 s, which keeps pans and walks); the shake is the RMS length of what is "
        "left, in px, and of its rotation alone, in degrees; its parts, the RMS of each "
        "component (x, y, roll, zoom), say what is left. Lower is steadier. --spread "
        "reads it again with each clip mirrored left-right, upside down and both (the same "
        "motion, other features and RANSAC draws) and gives the four readings' mean and "
        "range: a difference between two outputs smaller than that range is the metric's "
        "own noise. --sizes reads those four again with the registration at 576, 608, 672 "
        "and 704 px on the long side as well as 640: where its pyramid's grid falls on the "
        "picture moves a mean of four by about 3% (up to 7%), and the 20 average over it.\n\n"
        "Wobble (a rolling shutter's jello): of each frame-to-frame homography (the same "
        "matches, RANSAC), its linear part at the frame's centre [[a, b], [c, d]]; the part no "
        "similarity has, ((a - d)/2, (b + c)/2), the stretch and the shear, times half the "
        "clip's width; its RMS over the pairs, in px. About 0 for a global shutter; lower "
        "is better."
    )
)
def evaluate(
    original: Path = typer.Argument(
        ..., help="The input clip (or image sequence: frames/img-%d.jpg)."
    ),
    stabilised: Path = typer.Argument(..., help="Its stabilised version (from any tool)."),
    truth: Path | None = typer.Option(None, help="truth.csv of a rendered clip."),
    rotations: Path | None = typer.Option(
        None, help="An estimated rotations file (frame,t,rx,ry,rz,...) to score against --truth."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON on stdout."),
    plot: Path | None = typer.Option(
        None, help="Also draw the shake's parts of both clips over time, and the distortion (PNG)."
    ),
    spread: bool = typer.Option(
        False,
        "--spread",
        help="Also read the residual shake with each clip mirrored three ways: the mean and "
        "range of the four readings (the metric's own noise; about 4x the time).",
    ),
    sizes: bool = typer.Option(
        False,
        "--sizes",
        help="With --spread, read those four at five registration sizes (576-704 px on the "
        "long side): 20 readings a clip, steadier, about 20x the time.",
    ),
    fps: FpsOption = None,
    quiet: QuietOption = False,
) -> None:
    """Cropping ratio, distortion, stability, ITF, residual shake and wobble of a
    stabilised clip and its original."""
    from stabilize.evaluate.metrics import (
        REGISTRATION_LONG_SIDE,
        SPREAD_SIZES,
        evaluate_pair,
        shake_spread,
    )
    from stabilize.motion.files import angular_errors, read_rotations
    from stabilize.video import VideoError, probe, read_frames, sequence_args

    if (truth is None) != (rotations is None):
        fail("--truth and --rotations go together")
    if sizes and not spread:
        fail("--sizes reads the spread at more sizes: give --spread too")
    if plot is not None and plot.suffix.lower() != ".png":
        fail(f"--plot {plot}: give a .png file")
    if plot is not None and not plot.parent.is_dir():
        fail(f"--plot {plot}: no such folder {plot.parent}")
    if plot is not None:  # (an older plot is replaced; a folder, or an input, never)
        from stabilize.video.atomic import check_absent, check_not_input

        run_or_fail(lambda: check_not_input(plot, original, stabilised))
        run_or_fail(lambda: check_absent(plot, overwrite=True))
    try:
        info_o = probe(original, sequence_args(original, fps=fps))
        info_s = probe(stabilised, sequence_args(stabilised, fps=fps))
        size, fps = info_o.size, info_o.fps or 30.0
        with progress_bar("evaluating", None, quiet=quiet) as advance:
            before, after = evaluate_pair(
                read_frames(original, info=info_o),
                read_frames(stabilised, size, info_s),
                fps,
                advance,
            )
        result = {"original": before.as_dict(), "stabilised": after.as_dict()}
        if spread:
            total = before.frames + after.frames
            registered = SPREAD_SIZES if sizes else (REGISTRATION_LONG_SIDE,)
            with progress_bar("mirrored", total, quiet=quiet) as advance:
                for name, frames, m in (  # each clip as the pass above read it
                    ("original", read_frames(original, info=info_o), before),
                    ("stabilised", read_frames(stabilised, size, info_s), after),
                ):
                    shake = m.residual_shake_px
                    found = shake_spread(frames, shake, fps, advance, sizes=registered)
                    result[name]["residual_shake_spread_px"] = found.as_dict()
        if truth is not None:
            err = angular_errors(read_rotations(rotations), read_rotations(truth))
            result["rotations"] = {
                "pairs": len(err),
                "aae_deg": float(err.mean()),
                "median_deg": float(np.median(err)),
                "p95_deg": float(np.percentile(err, 95)),
            }
    except (VideoError, ValueError) as err:
        fail(str(err))
    if plot is not None:
        from stabilize.evaluate.plot import plot_shake
        from stabilize.video.atomic import atomic_output

        with atomic_output(plot, overwrite=True) as partial:  # (an older one is replaced)
            plot_shake(partial, before, after, fps)
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
        ("residual shake (px)", "residual_shake_px", "{:.3f}"),
        ("residual shake (deg)", "residual_shake_deg", "{:.4f}"),
        ("  x, y, roll, zoom (px)", "shake_components_px", "{:.2f}/{:.2f}/{:.2f}/{:.2f}"),
        ("wobble (px)", "wobble_px", "{:.3f}"),
        ("frames", "frames", "{}"),
    ]
    typer.echo(f"{'metric':26s}{'original':>12s}{'stabilised':>12s}")
    for label, key, fmt in rows:
        a, b = (_formatted(fmt, result[clip][key]) for clip in ("original", "stabilised"))
        typer.echo(f"{label:26s}{a:>12s}{b:>{max(12, len(b) + 1)}s}")
    if spread:
        spreads = [result[c]["residual_shake_spread_px"] for c in ("original", "stabilised")]
        a, b = (f"{x['mean']:.3f} ({x['min']:.3f}–{x['max']:.3f})" for x in spreads)
        read = "mirrored, at five sizes" if sizes else "mirrored"
        typer.echo(f"residual shake {read} (px): original {a}, stabilised {b}")
    if "rotations" in result:
        r = result["rotations"]
        typer.echo(
            f"rotation error vs truth: AAE {r['aae_deg']:.4f}°, median "
            f"{r['median_deg']:.4f}°, p95 {r['p95_deg']:.4f}° over {r['pairs']} pairs"
        )


def _formatted(fmt: str, value) -> str:
    """A value, or a list of them (the shake's parts), by a format."""
    return fmt.format(*value) if isinstance(value, list | tuple) else fmt.format(value)
