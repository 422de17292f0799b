"""A battery of bad and unusual inputs and options, as a new user would try them.

Each case runs the real command line (``main``) and asserts:

* the exit status: 0 for an unusual input that must work, 2 for a bad input or option,
  1 for a failure while working;
* where it fails, that stderr is one ``error:`` line (notices aside), no traceback;
* that the input is unchanged, and that nothing is left under the final name, nor a
  temporary file beside it;
* for every option and path mistake, that it is caught before any frame is decoded.
"""

from __future__ import annotations

import hashlib
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from stabilize.cli import main
from stabilize.video import ffmpeg_exe, probe
from tests.stabilize.helpers import SAMPLE

LOG = SAMPLE / "gyro.csv"


@dataclass(frozen=True)
class Case:
    args: tuple[str, ...]  # after IN OUT; "{dir}" is the case's folder
    status: int
    early: bool = True  # fails before any decoding
    source: str = "shaky"  # which input (see inputs())
    out: str = "out.mp4"
    container: str = ""  # for a success: the muxer FFmpeg reports, e.g. "matroska"
    files: dict = field(default_factory=dict)  # extra files: name → text


CASES = {
    # bad inputs
    "missing input": Case((), 2, source="missing"),
    "text file named .mp4": Case((), 2, source="text"),
    "empty file": Case((), 2, source="empty"),
    "folder as input": Case((), 2, source="folder"),
    "truncated video": Case((), 2, early=False, source="truncated"),
    "one frame": Case((), 2, early=False, source="one frame"),
    "audio only": Case((), 2, source="audio only"),
    "image sequence matching nothing": Case((), 2, source="no frames"),
    "image sequence with a gap": Case((), 2, source="gap"),
    # bad outputs
    "output is the input": Case((), 2, out="{input}"),
    "output exists": Case((), 2, out="exists.mp4", files={"exists.mp4": "keep me"}),
    "output folder is a file": Case((), 2, out="afile/out.mp4", files={"afile": "x"}),
    "output under /proc": Case((), 2, out="/proc/stabilize-test.mp4"),
    "unknown output suffix": Case((), 2, out="out.notacontainer"),
    "one picture for a clip": Case((), 2, out="out.png"),
    "pictures exist": Case((), 2, out="f%02d.png", files={"f07.png": "keep me"}),
    "video encoder for pictures": Case(("--codec", "libx264"), 2, out="f%02d.png"),
    "report is a file": Case(("--report", "{dir}/notes.txt"), 2, files={"notes.txt": "x"}),
    "rotations onto an existing file": Case(("-o", "{dir}/r.csv"), 2, files={"r.csv": "x"}),
    # a folder named as the output: it failed once the work was done, "Is a directory"
    "output is a folder": Case(("--overwrite",), 2, out="o.mp4", files={"o.mp4/keep": "x"}),
    "rotations onto a folder": Case(("-o", "{dir}/r", "--overwrite"), 2, files={"r/keep": "x"}),
    # bad options
    "unknown option": Case(("--frobnicate",), 2),
    "flow": Case(("--flow", "sift"), 2),
    "method": Case(("--method", "spline"), 2),
    "crop": Case(("--crop", "foo"), 2),
    "device": Case(("--device", "gpu"), 2),
    "preview": Case(("--preview", "stacked"), 2),
    "deinterlace": Case(("--deinterlace", "sideways"), 2),
    "bars": Case(("--bars", "sometimes"), 2),
    "fov zero": Case(("--fov", "0"), 2),
    "fov 200": Case(("--fov", "200"), 2),
    "focal negative": Case(("--focal", "-5"), 2),
    "smooth zero": Case(("--smooth", "0"), 2),
    "fps zero": Case(("--fps", "0"), 2, source="frames"),
    "max zoom below 1": Case(("--max-zoom", "0.5"), 2),
    "crf 99": Case(("--crf", "99"), 2),
    # FFmpeg wrote yuv420p instead, saying so only in a warning
    "pixel format the encoder does not write": Case(("--pix-fmt", "yuv410p"), 2),
    "no such pixel format": Case(("--pix-fmt", "yuv420"), 2),
    "unknown codec": Case(("--codec", "nope"), 2),
    "unknown preset": Case(("--preset", "nope"), 2),
    "size not WxH": Case(("--size", "big"), 2),
    "size odd": Case(("--size", "641x361"), 2),
    "size tiny": Case(("--size", "8x8"), 2),
    "readout without gyro": Case(("--readout-ms", "5"), 2),
    "readout not a number": Case(("--gyro", str(LOG), "--readout-ms", "fast"), 2),
    "rolling shutter not a number": Case(("--rolling-shutter", "fast"), 2),
    "rolling shutter too long": Case(("--rolling-shutter", "2000"), 2),
    "stretch over 100 %": Case(("--max-stretch", "150"), 2),
    "stretch negative": Case(("--max-stretch", "-1"), 2),
    "rolling shutter and readout": Case(
        ("--gyro", str(LOG), "--readout-ms", "5", "--rolling-shutter", "5"), 2
    ),
    "gyro log missing": Case(("--gyro", "{dir}/nope.csv"), 2),
    "gyro log empty": Case(("--gyro", "{dir}/empty.csv"), 2, files={"empty.csv": ""}),
    "gyro log garbage": Case(("--gyro", "{dir}/g.csv"), 2, files={"g.csv": "1,2\n3\n"}),
    "gyro axes letters": Case(("--gyro", str(LOG), "--gyro-axes", "XYQ"), 2),
    "gyro axes reflection": Case(("--gyro", str(LOG), "--gyro-axes", "XYz"), 2),
    "gyro format": Case(("--gyro", str(LOG), "--gyro-format", "foo"), 2),
    "gyro low-pass above Nyquist": Case(("--gyro", str(LOG), "--gyro-lpf", "10000"), 2),
    "gyro timestamps too few": Case(
        ("--gyro", str(LOG), "--gyro-timestamps", "{dir}/t.csv"), 2, files={"t.csv": "1\n2\n"}
    ),
    "lens missing": Case(("--lens", "{dir}/nope.json"), 2),
    "lens not JSON": Case(("--lens", "{dir}/l.json"), 2, files={"l.json": "{not json"}),
    "quiet first, bad input": Case(("-q",), 2, source="missing"),
    "cuda without a GPU": Case(("--device", "cuda"), 2),
    # unusual inputs and outputs that must work
    "odd frame size": Case((), 0, early=False, source="odd", container="mp4"),
    "mkv output": Case((), 0, early=False, out="out.mkv", container="matroska"),
    "webm output": Case((), 0, early=False, out="out.webm", container="matroska"),
    "avi output": Case((), 0, early=False, out="out.avi", container="avi"),
    "mov output": Case((), 0, early=False, out="out.mov", container="mov"),
    "ts output": Case((), 0, early=False, out="out.ts", container="mpegts"),
    "AVI MPEG-4 ASP input": Case((), 0, early=False, source="xvid.avi", container="mp4"),
    "MJPEG AVI input": Case((), 0, early=False, source="mjpeg.avi", container="mp4"),
    "MKV input": Case((), 0, early=False, source="x.mkv", container="mp4"),
    "MPEG-TS input": Case((), 0, early=False, source="x.ts", container="mp4"),
    "HEVC input, HEVC output": Case(
        ("--codec", "libx265"), 0, early=False, source="hevc.mp4", container="mp4"
    ),
    "VP9 WebM input": Case((), 0, early=False, source="vp9.webm", container="mp4"),
    "ProRes MOV input": Case((), 0, early=False, source="prores.mov", container="mp4"),
    "AV1 input": Case((), 0, early=False, source="av1.mkv", container="mp4"),
    "interlaced MPEG-2 TS input": Case((), 0, early=False, source="50i.ts", container="mp4"),
    # numbered from 7, as a sequence cut from a longer one is: FFmpeg alone tries 0–4
    "image sequence from 7": Case((), 0, early=False, source="frames", container="mp4"),
    "image sequence output": Case((), 0, early=False, out="pictures/%04d.png", container="image2"),
}
if shutil.which("nvidia-smi"):  # pragma: no cover - a machine with a GPU runs it
    CASES.pop("cuda without a GPU")

# FFmpeg arguments that make each unusual input from the shaky clip.
TRANSCODES = {
    "xvid.avi": ["-c:v", "mpeg4", "-vtag", "XVID", "-bf", "2", "-q:v", "4", "-c:a", "libmp3lame"],
    "mjpeg.avi": ["-c:v", "mjpeg", "-q:v", "4", "-c:a", "pcm_s16le"],
    "x.mkv": ["-c", "copy"],
    "x.ts": ["-c", "copy", "-f", "mpegts"],
    "hevc.mp4": ["-c:v", "libx265", "-preset", "ultrafast", "-tag:v", "hvc1", "-c:a", "copy"],
    "vp9.webm": ["-c:v", "libvpx-vp9", "-deadline", "realtime", "-c:a", "libopus"],
    "prores.mov": ["-c:v", "prores_ks", "-c:a", "copy"],
    "av1.mkv": ["-c:v", "libsvtav1", "-preset", "12", "-c:a", "copy"],
    "odd": ["-vf", "crop=319:179:0:0", "-c:v", "libx264", "-pix_fmt", "yuv444p", "-c:a", "copy"],
    "one frame": ["-frames:v", "1", "-an"],
    # a broadcast or camcorder recording: MPEG-2, fields woven top first
    "50i.ts": [
        *("-vf", "tinterlace=mode=interleave_top,setfield=tff", "-flags", "+ildct+ilme"),
        *("-c:v", "mpeg2video", "-q:v", "3", "-c:a", "mp2", "-f", "mpegts"),
    ],
}


def make_input(name: str, shaky: Path, folder: Path) -> Path:
    if name == "shaky":
        return shaky
    if name == "missing":
        return folder / "nope.mp4"
    if name == "folder":
        return folder
    if name in ("frames", "no frames", "gap"):
        pattern = folder / "img-%04d.png"
        cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "12"]
        if name != "no frames":
            subprocess.run([*cmd, "-start_number", "7", str(pattern)], check=True)
        if name == "gap":
            (folder / "img-0010.png").unlink()
        return pattern
    path = folder / {"odd": "odd.mp4", "one frame": "one.mp4"}.get(name, name)
    if name == "text":
        path = folder / "notes.mp4"
        path.write_text("this is not a video\n")
    elif name == "empty":
        path = folder / "empty.mp4"
        path.write_bytes(b"")
    elif name == "truncated":
        path = folder / "truncated.mp4"
        data = shaky.read_bytes()
        path.write_bytes(data[: len(data) // 3])
    elif name == "audio only":
        path = folder / "audio.m4a"
        cmd = [ffmpeg_exe(), "-v", "error", "-f", "lavfi", "-i", "sine=duration=1", str(path)]
        subprocess.run(cmd, check=True)
    else:
        cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shaky), *TRANSCODES[name], str(path)]
        subprocess.run(cmd, check=True)
    return path


def digest(path: Path) -> str | None:
    if not path.is_file():
        return None
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def no_decoding(monkeypatch):
    """Any decoding fails the test: the mistake had to be caught before it."""

    def refuse(*args, **kwargs):
        raise AssertionError("decoding started before the mistake was caught")

    monkeypatch.setattr("stabilize.motion.estimate.read_frames", refuse)
    monkeypatch.setattr("stabilize.warp.render.read_frames", refuse)


@pytest.mark.parametrize("name", list(CASES))
def test_the_battery(name, shaky, tmp_path, monkeypatch, capsys, request):
    case = CASES[name]
    for file, text in case.files.items():
        (tmp_path / file).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / file).write_text(text)
    source = make_input(case.source, shaky, tmp_path)
    out = Path(case.out.format(input=source)) if "{" in case.out else tmp_path / case.out
    if case.out.startswith("/"):
        out = Path(case.out)
    before, out_before = digest(source), digest(out)
    args = [a.format(dir=tmp_path) for a in case.args]
    command = ["rotations", str(source)] if "-o" in args else [str(source), str(out)]
    if case.early:
        request.getfixturevalue("no_decoding")
    monkeypatch.setattr("sys.argv", ["stabilize", *command, *args, "-q"])
    with pytest.raises(SystemExit) as done:
        main()
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith("notice:")]
    assert done.value.code == case.status, err
    assert "Traceback" not in err
    assert digest(source) == before  # the input is never modified
    if case.status:
        assert len(lines) == 1 and lines[0].startswith("error: "), err
        assert digest(out) == out_before  # nothing new (or changed) under the final name
    else:
        assert not lines, err
        assert probe(out).width % 2 == 0 and _muxer(out) == case.container
    if out.parent.is_dir() and not str(out).startswith("/proc"):
        assert not list(out.parent.glob(".*.partial*"))


def _muxer(path: Path) -> str:
    """The container FFmpeg finds in a file: mp4 and mov told apart by the brand."""
    text = subprocess.run(
        [ffmpeg_exe(), "-hide_banner", "-i", str(path)], capture_output=True, text=True
    ).stderr
    first = text[text.index("Input #0, ") + len("Input #0, ") :].split(",")[0]
    if first == "mov":
        return "mov" if "major_brand     : qt" in text else "mp4"
    return first


def test_the_battery_is_at_least_forty_cases():
    assert len(CASES) >= 40
    assert sum(c.status == 0 for c in CASES.values()) >= 10
