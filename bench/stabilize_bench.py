"""Our stabiliser against FFmpeg's vid.stab (two passes), side by side.

For each clip (rendered street clips by default, or the paths given) it runs

* ours: ``stabilize IN OUT`` with default settings (timed without ``--report``; on
  rendered clips a second run writes the report that the truth check reads);
* vid.stab: ``vidstabdetect`` then ``vidstabtransform`` with ``optzoom=1``,

both encoding with libx264, CRF 18, preset medium, and prints the wall time, the peak
memory (of the process tree), and the metrics of ``stabilize evaluate``. On rendered
clips it also prints the residual rotational jitter of our output against the truth:
the standard deviation of the high-passed angular velocity, as a share of the input's.

    python bench/stabilize_bench.py                      # two rendered 4 s street clips
    python bench/stabilize_bench.py ../shared/data/handheld/cockatoo.mp4
    python bench/stabilize_bench.py hd.mp4 --repeat 3         # three turns each
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from rotation import so3
from stabilize.evaluate.metrics import evaluate_pair
from stabilize.video import ffmpeg_exe, probe, read_frames
from stabilize.video.encoders import DEFAULT_CRF

OUT_CRF = DEFAULT_CRF["libx264"]  # both tools' output, as our default encodes it


def crf_option(text: str) -> int:
    """An x264 CRF as a command line gives it (argparse's ``type``): 0 to 51."""
    value = int(text)
    if not 0 <= value <= 51:
        raise argparse.ArgumentTypeError(f"must be between 0 and 51, got {value}")
    return value


def encoder(crf: int = OUT_CRF) -> list[str]:
    """FFmpeg's options for both tools' output: libx264 at ``crf`` (0: lossless), preset
    medium, 4:2:0."""
    return ["-c:v", "libx264", "-crf", str(crf), "-preset", "medium", "-pix_fmt", "yuv420p"]


def timed(cmd: list[str]) -> tuple[float, float]:
    """(wall seconds, peak RSS MB of the command's process tree)."""
    wrapper = (
        "import resource, subprocess, sys, time\n"
        "t = time.perf_counter()\n"
        "code = subprocess.call(sys.argv[1:])\n"
        "dt = time.perf_counter() - t\n"
        "peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024\n"
        "print(dt, peak)\n"
        "sys.exit(code)\n"
    )
    out = subprocess.run([sys.executable, "-c", wrapper, *cmd], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{cmd[0]} failed: {out.stderr.strip()[-400:]}")
    dt, peak = out.stdout.split()[-2:]
    return float(dt), float(peak)


def vidstab(src: Path, dst: Path, work: Path, crf: int = OUT_CRF) -> tuple[float, float]:
    trf = work / "transforms.trf"
    ff = [ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-y", "-i", str(src)]
    t1, m1 = timed([*ff, "-vf", f"vidstabdetect=result={trf}", "-f", "null", "-"])
    transform = ["-vf", f"vidstabtransform=input={trf}:optzoom=1", *encoder(crf)]
    t2, m2 = timed([*ff, *transform, "-c:a", "copy", str(dst)])
    return t1 + t2, max(m1, m2)


def ours(src: Path, dst: Path, report: Path | None = None) -> tuple[float, float]:
    cmd = [sys.executable, "-m", "stabilize.cli", "run", str(src), str(dst), "-q", "--overwrite"]
    return timed(cmd if report is None else [*cmd, "--report", str(report)])


def residual_jitter(report: Path, truth_json: Path) -> float | None:
    """Our output's high-passed angular-velocity std over the input's, from the truth."""
    from stabilize.synth import SynthOptions, trajectory

    meta = json.loads(truth_json.read_text())
    opts = SynthOptions(
        seed=meta["seed"],
        seconds=meta["seconds"],
        fps=meta["fps"],
        shake_deg=meta["shake_deg"],
        pan_deg=meta["pan_deg"],
        walk=meta["walk"],
        size=tuple(meta["size"]),
    )
    path = np.loadtxt(report / "path.csv", delimiter=",", skiprows=1)
    from scipy.spatial.transform import Rotation

    raw = Rotation.from_quat(path[:, 2:6], scalar_first=True).as_matrix()
    smooth = Rotation.from_quat(path[:, 6:10], scalar_first=True).as_matrix()
    O_true = trajectory.orientation(opts.motion, path[:, 1])
    out = smooth @ np.swapaxes(raw, -1, -2) @ O_true

    def jitter(O: np.ndarray) -> float:
        w = np.degrees(so3.log_so3(O[1:] @ np.swapaxes(O[:-1], -1, -2)))
        return float(np.std(np.diff(w, axis=0)))  # high-passed angular velocity

    return jitter(out) / jitter(O_true)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("clips", nargs="*", type=Path)
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument(
        "--repeat", type=int, default=1, help="time each tool this many times, taking turns"
    )
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="stab-bench-"))
    clips = list(args.clips)
    truths: dict[Path, Path] = {}
    if not clips:
        from stabilize.synth import SynthOptions, render_clip

        for seed in (1, 2):
            folder = work / f"street{seed}"
            render_clip(folder, SynthOptions(seed=seed, seconds=args.seconds, shake_deg=1.2))
            clips.append(folder / "clip.mp4")
            truths[clips[-1]] = folder / "truth.json"

    for clip in clips:
        info = probe(clip)
        print(f"\n{clip} ({info.width}x{info.height}, {info.fps:g} fps, {info.duration} s)")
        mine, theirs = work / f"{clip.stem}_ours.mp4", work / f"{clip.stem}_vidstab.mp4"
        report = work / f"{clip.parent.name}_{clip.stem}_report"
        # The default run is what is timed. The machine's speed drifts by ±10% over
        # minutes, so with --repeat the two tools take turns, and the ratio reported is
        # the median of each turn's ratio.
        runs = [(ours(clip, mine), vidstab(clip, theirs, work)) for _ in range(args.repeat)]
        (t_ours, m_ours), (t_vs, m_vs) = min(r[0] for r in runs), min(r[1] for r in runs)
        ratio = float(np.median([o[0] / v[0] for o, v in runs]))
        original, ours_m = evaluate_pair(read_frames(clip), read_frames(mine, info.size))
        _, theirs_m = evaluate_pair(read_frames(clip), read_frames(theirs, info.size))
        rows = {"original": original, "ours": ours_m, "vid.stab": theirs_m}
        print(
            f"{'':10s}{'wall s':>8s}{'peak MB':>9s}{'crop':>7s}{'distort':>8s}"
            f"{'stab T':>8s}{'stab R':>8s}{'stab':>7s}{'ITF dB':>8s}"
        )
        cost = {"original": ("", ""), "ours": (t_ours, m_ours), "vid.stab": (t_vs, m_vs)}
        for name, m in rows.items():
            t, mem = cost[name]
            t = f"{t:8.1f}" if t != "" else f"{'':8s}"
            mem = f"{mem:9.0f}" if mem != "" else f"{'':9s}"
            print(
                f"{name:10s}{t}{mem}{m.cropping_ratio:7.3f}{m.distortion:8.3f}"
                f"{m.stability_translation:8.3f}{m.stability_rotation:8.3f}"
                f"{m.stability:7.3f}{m.itf_db:8.2f}"
            )
        print(
            f"speed: ours takes {ratio:.2f}× vid.stab's wall time "
            f"(per turn: {', '.join(f'{o[0] / v[0]:.2f}' for o, v in runs)}); "
            f"{info.duration or 0:.1f} s of video in {t_ours:.1f} s"
        )
        if clip in truths:
            ours(clip, work / f"{clip.stem}_reported.mp4", report)
            share = residual_jitter(report, truths[clip])
            print(f"residual rotational jitter of our output: {100 * share:.1f}% of the input's")
    print(f"\n(outputs in {work})")


if __name__ == "__main__":
    main()
