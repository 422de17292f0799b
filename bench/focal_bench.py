"""The focal length found from the clip itself (``--fov auto``, the default) against the truth.

Rendered walks past near walls with a crowd (960×540, 4 s, a handheld walk whose bob and
sway at 1.8 Hz the search's running median does not remove) at fields of view from 30° to
110°, a few seeds each, and phone-cc9's real frames (their calibration: 573.85 px), whole
and zoomed in to 50°, 38°, 31°, 26° and 24° about the principal point, as a phone's
digital zoom does (there f is the calibration times the zoom), encoded at ``--crf``.
For each clip: the f found and its source (``estimated``, or ``default`` where the
motion does not pin it down and does not rule the default out), its error, and pass 1's
time. With ``--shake``, each rendered clip is also stabilised twice, given its
true field of view and with the default, and the residual shake of both outputs
(``stabilize evaluate``) is given: issue #15 asks the estimate's to be within 5%. On
these walks past near walls the metric's registration picks between depth layers, so
one reading moves by up to 20% between outputs that differ by 2 grey levels (90°, f found
within 0.01%: 0.630 against 0.760 px): each output is read as it is and mirrored three
ways (``real_bench.py --spread``), and the four readings' mean and range are given.

    python bench/focal_bench.py
    python bench/focal_bench.py --fov 110 --seeds 8 11 12 --shake
    python bench/focal_bench.py --fov 30 --seeds 2 --walk 0    # the same hand, standing
    python bench/focal_bench.py --fov 30 --flow raft    # RAFT's flow (its weights: README)
    python bench/focal_bench.py --fov 30 --exact    # the search on the exact rotational flow
    python bench/focal_bench.py --fov --crf 28    # phone-cc9's views alone, as shared clips
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import flow
from rotation import HoughEstimator, so3
from stabilize import Settings
from stabilize.evaluate.metrics import evaluate_pair
from stabilize.motion.files import read_rotations
from stabilize.motion.focal import FocalChoice, estimate_motion, focal_from_track
from stabilize.motion.track import VisualTrack
from stabilize.synth import SynthOptions, render_clip
from stabilize.video import probe, read_frames

sys.path.insert(0, str(Path(__file__).resolve().parent))
from real_bench import PHONE, WALK, ZOOM_CROP, mirrored, phone_clip, span

PHONE_FOCAL = 573.85  # px at its frames' 800×600, their calibration
# (FFmpeg filter, zoom): its frames' middle about the principal point (406.01, 309.01),
# shown at 640×480
ZOOMS = {
    "whole": (None, 1.0),
    "zoom 50°": ("crop=534:400:139:109,scale=640:480", 640 / 534),
    "zoom 38°": ("crop=400:300:206:159,scale=640:480", 640 / 400),
    "zoom 31°": (ZOOM_CROP, 2.0),
    "zoom 26°": ("crop=266:200:273:209,scale=640:480", 640 / 266),
    "zoom 24°": ("crop=240:180:286:219,scale=640:480", 640 / 240),
}


def rendered(work: Path, fov: float, seed: int, walk: float = WALK) -> tuple[Path, float]:
    """A rendered walk at ``fov`` (at ``walk`` m/s; 0: the same hand, standing) and its
    true focal length (px)."""
    folder = work / f"walk{fov:g}_s{seed}"
    render_clip(folder, SynthOptions(seed=seed, seconds=4.0, hfov=fov, walk=walk))
    return folder / "clip.mp4", json.loads((folder / "truth.json").read_text())["K"][0][0]


def phone(work: Path, name: str, crf: int = 12) -> tuple[Path, float]:
    """phone-cc9's frames as a clip encoded at ``crf``, whole or zoomed in (``ZOOMS``),
    and the focal length (px) that view has."""
    view, zoom = ZOOMS[name]
    clip = work / f"phone-cc9_{name.replace(' ', '').replace('°', '')}.mp4"
    return phone_clip(clip, view, crf), PHONE_FOCAL * zoom


def exact_error(clip: Path, track: VisualTrack, focal: FocalChoice, truth: float) -> float:
    """The search's error (%) on a rendered walk's pass-1 ``track`` (estimated at
    ``focal``, its samples kept) with every kept vector replaced by the flow its true
    rotation gives at its true focal length: no parallax, no crowd, no flow error, so what
    is left is the search's own (the same pairs, samples and validity)."""
    info = probe(clip)
    size = flow.working_size(info.size)
    estimator = HoughEstimator(size.size, focal.px * size.scale[0])
    x, y, f = estimator.grid.x, estimator.grid.y, truth * size.scale[0]
    rotations = read_rotations(clip.parent / "truth.csv")
    turns = so3.exp_so3(np.array([rotations[k] for k in range(len(track.rotations))]))
    rays = turns @ np.stack([x, y, np.full_like(x, f)])
    u, v = f * rays[:, 0] / rays[:, 2] - x, f * rays[:, 1] / rays[:, 2] - y
    exact = replace(track, samples=replace(track.samples, u=u, v=v))
    found = focal_from_track(exact, estimator, max(info.size) * size.scale[0]).focal
    return math.nan if found is None else 100 * (found / f - 1)


def shake(clip: Path, out: Path, options: list[str]) -> list[float]:
    """The residual shake (px) of ``clip`` stabilised with ``options``, read as it is
    and mirrored three ways."""
    cmd = [sys.executable, "-m", "stabilize.cli", "run", str(clip), str(out), "-q", "--overwrite"]
    subprocess.run([*cmd, *options], check=True, capture_output=True)
    info = probe(clip)
    fps = info.fps or 30.0
    _, m = evaluate_pair(read_frames(clip), read_frames(out, info.size), fps)
    return mirrored(out, info.size, fps, m)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--fov", type=float, nargs="*", default=[30, 45, 70, 90, 100, 110], help="none: no walks"
    )
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--walk", type=float, default=WALK, help="walking speed, m/s (0: standing)")
    parser.add_argument("--flow", default="dis", choices=sorted(flow.BACKENDS))
    parser.add_argument("--crf", type=int, default=12, help="phone-cc9's views' x264 CRF")
    parser.add_argument("--shake", action="store_true", help="stabilise each walk at both f")
    parser.add_argument(
        "--exact", action="store_true", help="also search each walk's exact rotational flow"
    )
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="focal-bench-"))
    clips = [
        (f"walk {fov:g}° seed {s}", *rendered(work, fov, s, args.walk))
        for fov in args.fov
        for s in args.seeds
    ]
    if PHONE.is_dir():
        clips += [(f"phone-cc9 {name}", *phone(work, name, args.crf)) for name in ZOOMS]
    print(
        f"{'clip':26s}{'true f':>9s}{'found':>9s}{'source':>11s}{'error':>8s}{'pass 1 s':>10s}",
        end="",
    )
    print(f"{'exact flow':>12s}" if args.exact else "", end="")
    print(f"   {'shake: true f (mirrored)':26s}  {'found':23s}" if args.shake else "")
    errors = []
    for name, clip, truth in clips:
        info = probe(clip)
        start = time.perf_counter()
        track, focal = estimate_motion(
            clip, info, Settings(flow=args.flow), keep_samples=args.exact
        )
        seconds = time.perf_counter() - start
        error = 100 * (focal.px / truth - 1)
        if focal.source == "estimated" and name.startswith("walk"):
            errors.append(abs(error))
        row = (
            f"{name:26s}{truth:9.1f}{focal.px:9.1f}{focal.source:>11s}{error:+7.1f}%{seconds:10.2f}"
        )
        if args.exact and name.startswith("walk"):
            row += f"{exact_error(clip, track, focal, truth):+11.2f}%"
        if args.shake and name.startswith("walk"):
            fov = math.degrees(2 * math.atan(info.width / 2 / truth))
            flows = ["--flow", args.flow]
            given = shake(
                clip, work / f"{clip.parent.name}_given.mp4", ["--fov", f"{fov:.4f}", *flows]
            )
            found = shake(clip, work / f"{clip.parent.name}_found.mp4", flows)
            ratio = 100 * (np.mean(found) / np.mean(given) - 1)
            row += f"   {span(given)}  {span(found)}  {ratio:+.1f}%"
        print(row, flush=True)
    if errors:
        within = sum(e <= 3 for e in errors)
        print(
            f"\nrendered walks estimated: {len(errors)}; within 3%: {within}; within 1%: "
            f"{sum(e <= 1 for e in errors)}; worst {max(errors):.1f}%; clips in {work}"
        )


if __name__ == "__main__":
    main()
