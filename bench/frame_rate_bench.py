"""High frame rates: the same rendered walk at 30, 60, 120 and 240 fps, ours and vid.stab.

A clip shot at 240 fps and watched at real speed shows what happens from one thirtieth of
a second to the next, as a 30 fps clip does. Its frame-to-frame residual shake reads an
eighth of that, though, since each frame moves an eighth as far. So each output, and the
original, is read at 30 fps: every (fps/30)-th frame, encoded losslessly. For each rate
this prints the original's and each tool's residual shake a thirtieth of a second (px,
x / y / roll / zoom), the focal length our run estimated (against the truth), the
readout it took and its time. The walk is rendered from one seed at every rate: the same
motion, sampled more often.

    python bench/frame_rate_bench.py
    python bench/frame_rate_bench.py --fps 30 240 --seconds 4 --seed 2
    python bench/frame_rate_bench.py --scene distant      # no walk, no crowd: a turn alone
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from stabilize_bench import vidstab

from stabilize.evaluate.metrics import evaluate_against
from stabilize.synth import SynthOptions, render_clip
from stabilize.video import ffmpeg_exe, read_frames

SCENES = {
    "walk": {},  # the synth's default street: a walk, a crowd, walls
    "distant": {"walk": 0.0, "crowd": 0},  # the camera only turns
}


def at_30_fps(src: Path, dst: Path, fps: float) -> Path:
    """Every (fps/30)-th frame of ``src``, losslessly, at 30 fps."""
    every = max(1, round(fps / 30))
    pick = f"select=not(mod(n\\,{every})),setpts=N/30/TB"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(src), "-vf", pick, "-r", "30"]
    subprocess.run([*cmd, "-c:v", "libx264", "-crf", "0", "-an", str(dst)], check=True)
    return dst


def ours(src: Path, dst: Path) -> tuple[dict, float]:
    """Our default run's summary, and its time."""
    cmd = [sys.executable, "-m", "stabilize", "run", str(src), str(dst), "-q", "--json"]
    start = time.perf_counter()
    out = subprocess.run([*cmd, "--overwrite"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout), time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--fps", type=float, nargs="+", default=[30.0, 60.0, 120.0, 240.0])
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scene", choices=sorted(SCENES), default="walk")
    args = parser.parse_args()
    head = f"{'fps':>5s} {'tool':9s}{'shake px':>9s}   x / y / roll / zoom px"
    print(f"{head}      f (true)     readout  s")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for fps in args.fps:
            folder = work / f"{args.scene}{fps:g}"
            options = SynthOptions(seed=args.seed, seconds=args.seconds, fps=fps)
            render_clip(folder, replace(options, **SCENES[args.scene]))
            clip = folder / "clip.mp4"
            truth = json.loads((folder / "truth.json").read_text())
            summary, took = ours(clip, folder / "ours.mp4")
            theirs_s, _ = vidstab(clip, folder / "vidstab.mp4", work)
            runs = [at_30_fps(folder / f"{name}.mp4", folder / f"{name}30.mp4", fps)
                    for name in ("ours", "vidstab")]  # fmt: skip
            original = at_30_fps(clip, folder / "original30.mp4", fps)
            before, after = evaluate_against(read_frames(original), [read_frames(r) for r in runs])
            focal = f"{summary['focal']['px']:6.1f} ({truth['K'][0][0]:6.1f})"
            readout = summary["rolling_shutter"]["readout_ms"]
            rows = [("original", before, "", ""), ("ours", after[0], focal, f"{took:5.1f}"),
                    ("vid.stab", after[1], "", f"{theirs_s:5.1f}")]  # fmt: skip
            for name, m, f, s in rows:
                parts = " / ".join(f"{p:.2f}" for p in m.shake_components_px)
                shown = f"{readout:5.1f} ms" if name == "ours" else ""
                row = f"{fps:5g} {name:9s}{m.residual_shake_px:9.3f}   {parts:26s}"
                print(f"{row}{f:>18s} {shown:>8s} {s}")


if __name__ == "__main__":
    main()
