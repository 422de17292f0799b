"""Batch speedup: 4 short rendered clips stabilised with 1 and with 2 workers.

python bench/batch_bench.py            # 4 clips of 3 s at 640×360
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from stabilize.synth import SynthOptions, render_clip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clips", type=int, default=4)
    parser.add_argument("--seconds", type=float, default=3.0)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="batch-bench-"))
    src = work / "in"
    for k in range(args.clips):
        render_clip(work / f"r{k}", SynthOptions(seed=k, seconds=args.seconds, size=(360, 640)))
        src.mkdir(exist_ok=True)
        (work / f"r{k}" / "clip.mp4").rename(src / f"clip{k}.mp4")
    times = {}
    for workers in (1, 2):
        out = work / f"out{workers}"
        t0 = time.perf_counter()
        subprocess.run(
            [
                sys.executable,
                "-m",
                "stabilize.cli",
                "batch",
                str(src),
                str(out),
                "--workers",
                str(workers),
                "-q",
            ],
            check=True,
        )
        times[workers] = time.perf_counter() - t0
        rows = json.loads((out / "manifest.json").read_text())
        peak = max(row.get("peak_mb", 0.0) for row in rows)
        print(
            f"{workers} worker(s): {times[workers]:.1f} s for {args.clips} clips, "
            f"peak memory per worker {peak:.0f} MB"
        )
    print(f"speedup with 2 workers: {times[1] / times[2]:.2f}×")


if __name__ == "__main__":
    main()
