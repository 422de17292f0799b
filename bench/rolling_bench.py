"""Rolling shutter without a gyro: the readout found from the video, and the wobble left.

Rendered street clips (540×960, 4 s, 3° RMS shake: 1–3° a frame) with readouts of 0, 15,
25 and 33 ms are stabilised three times at the true field of view: with
``--rolling-shutter auto`` (the default: the correction within ``--max-stretch`` 0.8%),
with the whole correction (``--max-stretch 100``), and ``off``; the table gives the
readout found, its uncertainty, and the residual shake, the wobble and the distortion
(``stabilize evaluate``) of each output. phone-cc9's frames, whose gyro gives a 25.4 ms readout
(``stabilize compare``), are run at their focal length, 573.85 px.

    python bench/rolling_bench.py
    python bench/rolling_bench.py --readouts 25 --seconds 2
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from stabilize.evaluate.metrics import evaluate_pair
from stabilize.synth import SynthOptions, render_clip
from stabilize.video import probe, read_frames

sys.path.insert(0, str(Path(__file__).resolve().parent))
from real_bench import PHONE, phone_clip

PHONE_FOCAL = "573.85"


VARIANTS = {  # the three runs of each clip
    "auto": ["--rolling-shutter", "auto"],
    "whole": ["--rolling-shutter", "auto", "--max-stretch", "100"],
    "off": ["--rolling-shutter", "off"],
}


def stabilise(clip: Path, out: Path, options: list[str], lens: list[str]) -> tuple[dict, float]:
    """Our run's summary and wall time."""
    cmd = [sys.executable, "-m", "stabilize.cli", "run", str(clip), str(out), "-q", "--json"]
    start = time.perf_counter()
    done = subprocess.run(
        [*cmd, "--overwrite", *options, *lens],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(done.stdout), time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--readouts", type=float, nargs="*", default=[0.0, 15.0, 25.0, 33.0])
    parser.add_argument("--seconds", type=float, default=4.0)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="rolling-bench-"))
    runs = []
    for ms in args.readouts:
        folder = work / f"rs{ms:g}"
        opts = SynthOptions(
            seed=7 + int(ms), seconds=args.seconds, shake_deg=3.0, rolling_shutter_ms=ms
        )
        render_clip(folder, opts)
        runs.append((f"rendered, {ms:g} ms", folder / "clip.mp4", ["--fov", str(opts.hfov)]))
    if PHONE.is_dir():
        runs.append(
            (
                "phone-cc9 (gyro: 25.4 ms)",
                phone_clip(work / "phone-cc9.mp4"),
                ["--focal", PHONE_FOCAL],
            )
        )
    print(
        f"{'clip':28s}{'readout found':>26s}{'shake auto/whole/off':>22s}"
        f"{'wobble auto/whole/off':>23s}{'distortion auto/whole/off':>27s}{'s auto/off':>12s}"
    )
    for name, clip, lens in runs:
        info = probe(clip)
        found, seconds, metrics = None, [], []
        for variant, options in VARIANTS.items():
            out = work / f"{clip.parent.name}-{clip.stem}-{variant}.mp4"
            summary, t = stabilise(clip, out, options, lens)
            found = found or summary["rolling_shutter"]
            seconds.append(t)
            _, after = evaluate_pair(read_frames(clip, info=info), read_frames(out, info.size))
            metrics.append(after)
        estimate = found["estimate_ms"]
        told = "-" if estimate is None else f"{estimate:.1f} ± {found['stderr_ms']:.1f} ms"
        told = f"{told} ({found['source']}{', used' if found['readout_ms'] else ''})"
        shake = "/".join(f"{m.residual_shake_px:.3f}" for m in metrics)
        wobble = "/".join(f"{m.wobble_px:.3f}" for m in metrics)
        distortion = "/".join(f"{m.distortion:.3f}" for m in metrics)
        print(
            f"{name:28s}{told:>26s}{shake:>22s}{wobble:>23s}{distortion:>27s}"
            f"{seconds[0]:>7.1f}/{seconds[-1]:<5.1f}"
        )
    print(f"\noutputs in {work}")


if __name__ == "__main__":
    main()
