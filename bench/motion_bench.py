"""What the 2-D correction on top of the rotation (``--motion``) removes from rendered
walks past near walls, against what the metric reads where there is no shake at all.

Each walk (real_bench's: 540×960, 4 s, 1.4 m/s, at 30°, 45° and 100°) is rendered four
ways from the same seed: as real_bench renders it (hand shake, bob and sway), with the
hand shake alone, with the bob and sway alone, and steady (no shake, no bob, no sway: a
dolly down the street, still panning). A distant scene is rendered beside them (no walk,
no walls: the camera only turns), where the rotation alone is exact; and a real one
as well, GoPro's karma (a drone high over a coast), where ../shared has it.

Each clip is stabilised with every ``--motion`` at its true field of view, at
``--max-zoom 1.5`` by default, where the budget does not bind (at the default 1.15 the
30° walk's bob does not fit in the crop, and the budget decides). karma is taken as a
user's run would take it, at the field of view found from it and the default budget (at
1.5 its path fits, and the crop that its last turns need is spent on all of it: 0.77).
For each it prints the residual shake (px; ``stabilize evaluate``), its ratio to the
rotation-only run's, and distortion and crop; with ``--spread``, the shake is the mean of
the four mirrored readings (real_bench's), steadier than one reading. The steady walk
says what the metric reads on a camera that does not shake at all (the walk's parallax,
the walking people, the pan), as it is and stabilised: a run on a shaking walk is not
expected to read much under its outputs.

    python bench/motion_bench.py
    python bench/motion_bench.py --fov 45 --max-zoom 1.15
    python bench/motion_bench.py --spread          # mirrored means: slower, steadier
    python bench/motion_bench.py --spread --sizes  # 20 readings each: slower still, finer
    python bench/motion_bench.py --out-crf 0 --only distant   # the geometry alone

``--out-crf`` sets the CRF every output is encoded at (18, the default's; 0: lossless,
so that a row reads the warps and not x264's response to them: real_bench's); ``--only``
keeps the rendered scenes whose names start with one of its words. With ``--sizes`` the
mean is of 20 readings: the four mirrored ones at each of the registration's five sizes
(real_bench's), since the four share where the registration's grid falls on the
picture, which moves their mean by about ±3%.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from stabilize import Settings, stabilize_video
from stabilize.evaluate.metrics import (
    REGISTRATION_LONG_SIDE,
    SPREAD_SIZES,
    evaluate,
    evaluate_against,
)
from stabilize.path.residual import MOTION_MODELS
from stabilize.synth import SynthOptions, render_clip
from stabilize.video import probe, read_frames
from stabilize.video.encode import Encoding
from stabilize.video.encoders import DEFAULT_CRF

sys.path.insert(0, str(Path(__file__).resolve().parent))
from real_bench import SHARED, mirrored, walk_options
from stabilize_bench import crf_option

KARMA = SHARED / "gopro" / "karma.mp4"  # a real distant scene: the rotation all but exact


def variants(fov: float) -> dict[str, SynthOptions]:
    """The walk at ``fov`` as real_bench renders it, and with parts of its motion off."""
    walk = walk_options(fov)
    return {
        "walk": walk,
        "hand shake alone": replace(walk, bob_m=0.0, sway_m=0.0),
        "bob and sway alone": replace(walk, shake_deg=0.0),
        "steady (no shake)": replace(walk, shake_deg=0.0, bob_m=0.0, sway_m=0.0),
        "distant scene": replace(walk, walk=0.0, walls=False),
    }


def shakes(
    clip: Path,
    outs: list[Path],
    spread: bool = False,
    sizes: tuple[int, ...] = (REGISTRATION_LONG_SIDE,),
) -> list[tuple[float, float, float]]:
    """(residual shake px, distortion, crop) of each of ``outs``, stabilised from ``clip``
    and read in one pass over it; with ``spread``, the shake is the mean of its four
    mirrored readings at each of the registration's ``sizes``."""
    info = probe(clip)
    outputs = [read_frames(out, info.size) for out in outs]
    _, found = evaluate_against(read_frames(clip), outputs, info.fps)
    readings = []
    for out, metrics in zip(outs, found, strict=True):
        px = metrics.residual_shake_px
        if spread:
            px = float(np.mean(mirrored(out, info.size, info.fps, metrics, sizes)))
        readings.append((px, metrics.distortion, metrics.cropping_ratio))
    return readings


def row(
    clip: Path,
    folder: Path,
    fov: float | None,
    max_zoom: float,
    crf: int,
    spread: bool = False,
    sizes: tuple[int, ...] = (REGISTRATION_LONG_SIDE,),
) -> tuple[str, str, str]:
    """The table's cells for ``clip`` stabilised with every ``--motion`` (at ``fov``;
    None: as a user would run it, the focal length found from the clip) and encoded at
    ``crf``: the shake of each (read as :func:`shakes` does), with its ratio to the
    rotation-only run's, then distortion and crop."""
    encoding = Encoding(crf=crf)
    outs = [folder / f"{motion}.mp4" for motion in MOTION_MODELS]
    for motion, out in zip(MOTION_MODELS, outs, strict=True):
        settings = Settings(motion=motion, fov=fov, max_zoom=max_zoom, encoding=encoding)
        stabilize_video(clip, out, settings, overwrite=True)
    readings = shakes(clip, outs, spread, sizes)
    base = readings[0][0]
    cells = " | ".join(f"{r[0]:.3f} ({r[0] / base:.2f})" for r in readings)
    dist = " / ".join(f"{r[1]:.3f}" for r in readings)
    return cells, dist, " / ".join(f"{r[2]:.3f}" for r in readings)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fov", type=float, nargs="+", default=[30.0, 45.0, 100.0])
    parser.add_argument("--max-zoom", type=float, default=1.5)
    parser.add_argument("--spread", action="store_true", help="mean of four mirrored readings")
    parser.add_argument(
        "--sizes",
        action="store_true",
        help="with --spread, read at the registration's five sizes too (20 readings)",
    )
    parser.add_argument(
        "--out-crf",
        type=crf_option,
        default=DEFAULT_CRF["libx264"],
        help="encode outputs at this CRF",
    )
    parser.add_argument("--only", nargs="+", help="keep the scenes named so (e.g. distant)")
    args = parser.parse_args()
    if args.sizes and not args.spread:
        parser.error("--sizes reads the spread: give --spread too")
    sizes = SPREAD_SIZES if args.sizes else (REGISTRATION_LONG_SIDE,)
    work = Path(tempfile.mkdtemp(prefix="motion-bench-"))
    motions = list(MOTION_MODELS)
    print(f"clips and outputs in {work}; --max-zoom {args.max_zoom}, true field of view,")
    print(f"outputs at CRF {args.out_crf}")
    print("| walk | clip | original | " + " | ".join(motions) + " | distortion | crop |")
    print("|---|---|---|" + "---|" * (len(motions) + 2))
    for fov in args.fov:
        for name, opts in variants(fov).items():
            if args.only and not any(name.startswith(word) for word in args.only):
                continue
            folder = work / f"{int(fov)}-{name.split()[0]}"
            render_clip(folder, opts)
            clip = folder / "clip.mp4"
            cells, dist, crop = row(
                clip, folder, fov, args.max_zoom, args.out_crf, args.spread, sizes
            )
            original = evaluate(read_frames(clip), opts.fps).residual_shake_px
            print(f"| {fov:g}° | {name} | {original:.3f} | {cells} | {dist} | {crop} |")
    # karma as a user's run: its field of view found from it, the default budget
    if KARMA.is_file() and (not args.only or "karma" in args.only):
        folder = work / "karma"
        folder.mkdir()
        zoom = Settings().max_zoom
        cells, dist, crop = row(KARMA, folder, None, zoom, args.out_crf, args.spread, sizes)
        original = evaluate(read_frames(KARMA), probe(KARMA).fps).residual_shake_px
        print(f"| real | karma (distant) | {original:.3f} | {cells} | {dist} | {crop} |")


if __name__ == "__main__":
    main()
