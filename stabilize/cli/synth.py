"""``stabilize synth``: render a shaky street clip with exact truth and a gyro log."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from stabilize.cli.app import app, fail
from stabilize.cli.options import OverwriteOption, QuietOption, output_size


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
    bob_m: float = typer.Option(0.02, min=0.0, help="Walking's vertical bob (amplitude), m."),
    sway_m: float = typer.Option(0.015, min=0.0, help="Walking's lateral sway (amplitude), m."),
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
    overwrite: OverwriteOption = False,
    quiet: QuietOption = False,
) -> None:
    """Render a shaky handheld street clip whose every rotation is known, with its gyro log."""
    from stabilize.cli.bars import progress_bar
    from stabilize.synth import SYNTH_FILES, SynthOptions, render_clip

    # a folder of one's own clips may hold a clip.mp4: replaced silently before
    found = [name for name in SYNTH_FILES if (out_dir / name).exists()]
    if found and not overwrite:
        fail(f"{out_dir} holds {', '.join(found)} (use --overwrite to replace them)")
    bg = None if procedural else (background or _default_panorama())
    if bg is not None and not Path(bg).is_file():
        fail(f"background image not found: {bg}")
    opts = SynthOptions(
        seed=seed,
        seconds=seconds,
        fps=fps,
        size=output_size(size),
        hfov=hfov,
        crowd=crowd,
        walls=walls,
        shake_deg=shake_deg,
        pan_deg=pan_deg,
        walk=walk,
        bob_m=bob_m,
        sway_m=sway_m,
        rolling_shutter_ms=rolling_shutter_ms,
        gyro_offset=gyro_offset,
        background=str(bg) if bg else None,
    )
    with progress_bar("rendering", opts.n_frames, unit="frames", quiet=quiet) as advance:
        summary = render_clip(out_dir, opts, advance)
    typer.echo(json.dumps(summary, indent=2))
