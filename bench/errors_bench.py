"""How long a mistake takes to be reported: each option or path error of the battery, run
as a user would (a fresh ``stabilize`` process) on a 30 s 1080p clip.

Every one must arrive before decoding starts, so the time is start-up plus the checks,
not a pass over the clip (the target: within 1.5 s here).

    python bench/errors_bench.py                # renders /tmp/errors-bench/clip.mp4 once
    python bench/errors_bench.py --clip my.mp4
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

from stabilize.video import ffmpeg_exe

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.stabilize.cli.test_battery import CASES  # noqa: E402


def clip(folder: Path) -> Path:
    """A 30 s 1080p30 clip with audio (a test pattern: these checks never decode it)."""
    path = folder / "clip.mp4"
    if not path.is_file():
        folder.mkdir(parents=True, exist_ok=True)
        cmd = [
            ffmpeg_exe(),
            "-v",
            "error",
            "-y",
            "-f",
            "lavfi",
            "-i",
            "testsrc2=s=1920x1080:r=30:d=30",
        ]
        cmd += ["-f", "lavfi", "-i", "sine=duration=30", "-c:v", "libx264", "-preset", "ultrafast"]
        subprocess.run([*cmd, "-c:a", "aac", "-shortest", str(path)], check=True)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clip", type=Path)
    args = parser.parse_args()
    folder = Path("/tmp/errors-bench")
    source = args.clip or clip(folder)
    times = {}
    for name, case in CASES.items():
        if not case.early or case.status == 0 or case.source != "shaky":
            continue
        for file, text in case.files.items():
            (folder / file).write_text(text)
        extra = [a.format(dir=folder) for a in case.args]
        out = folder / case.out if "{" not in case.out else source
        if case.out.startswith("/"):
            out = Path(case.out)
        command = ["rotations", str(source)] if "-o" in extra else [str(source), str(out)]
        start = time.perf_counter()
        result = subprocess.run(
            [
                sys.executable,
                "-c",
                "from stabilize.cli import main; main()",
                *command,
                *extra,
                "-q",
            ],
            capture_output=True,
            text=True,
        )
        times[name] = time.perf_counter() - start
        status = "ok" if result.returncode == case.status else f"EXIT {result.returncode}"
        print(f"{name:36s} {times[name]:5.2f} s  {status}  {result.stderr.strip()[:70]}")
    print(
        f"\n{len(times)} early errors on a 30 s 1080p clip: median "
        f"{statistics.median(times.values()):.2f} s, slowest {max(times.values()):.2f} s"
    )


if __name__ == "__main__":
    main()
