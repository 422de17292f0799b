"""How every command ends when it fails: one ``error:`` line and a status, never a
traceback (unless asked for)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from stabilize.cli import main
from stabilize.cli.app import LONGEST, one_line
from stabilize.video import ffmpeg_exe
from tests.stabilize.helpers import SAMPLE


def test_a_message_is_one_line_however_it_came():
    # numpy puts a whole array into some of its messages, over many lines
    message = f"Out of bounds w/ x = {np.linspace(0, 3, 400)}"
    assert "\n" in message
    line = one_line(message)
    assert "\n" not in line and len(line) == LONGEST and line.endswith("…")
    assert one_line("  no such\n file ") == "no such file"


def stabilising_fails(monkeypatch, tmp_path, error: Exception) -> tuple[str, str]:
    def broken(*args, **kwargs):
        raise error

    monkeypatch.setattr("stabilize.pipeline.stabilize_video", broken)
    clip = tmp_path / "in.mp4"
    clip.write_bytes(b"")  # never read: the job fails first
    out = tmp_path / "out.mp4"
    monkeypatch.setattr("sys.argv", ["stabilize", str(clip), str(out), "-q"])
    return str(clip), str(out)


def test_a_fault_of_ours_is_one_line_and_status_1(monkeypatch, tmp_path, capsys):
    _, out = stabilising_fails(monkeypatch, tmp_path, IndexError("index 150 is out of bounds"))
    monkeypatch.delenv("STABILIZE_DEBUG", raising=False)
    with pytest.raises(SystemExit) as done:
        main()
    err = capsys.readouterr().err.strip()
    assert done.value.code == 1 and "\n" not in err and "Traceback" not in err
    assert err.startswith("error: internal error (IndexError: index 150 is out of bounds)")
    assert "STABILIZE_DEBUG=1" in err
    assert not Path(out).exists()


def test_asked_for_the_traceback_raises(monkeypatch, tmp_path):
    stabilising_fails(monkeypatch, tmp_path, IndexError("index 150 is out of bounds"))
    monkeypatch.setenv("STABILIZE_DEBUG", "1")
    with pytest.raises(IndexError):
        main()


def test_a_bad_input_with_a_long_message_is_one_line_and_status_2(monkeypatch, tmp_path, capsys):
    stabilising_fails(monkeypatch, tmp_path, ValueError("first line\nsecond line"))
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 2
    assert capsys.readouterr().err.strip() == "error: first line second line"


def test_ctrl_c_is_one_line_and_status_130(monkeypatch, tmp_path, capsys):
    # typer turns a KeyboardInterrupt within a command into exit status 130 and prints
    # nothing; the user still gets the line
    _, out = stabilising_fails(monkeypatch, tmp_path, KeyboardInterrupt())
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: interrupted"), err
    assert not Path(out).exists()


def test_sigterm_is_one_line_and_status_143(monkeypatch, tmp_path, capsys):
    def terminated(*args, **kwargs):  # `kill`, `timeout`, a job scheduler
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # (the handler interrupts this)

    def unheard(*_):  # this test's own, so that a SIGTERM main() misses ends no run
        raise RuntimeError("main() set no handler for SIGTERM")

    monkeypatch.setattr("stabilize.pipeline.stabilize_video", terminated)
    clip, out = tmp_path / "in.mp4", tmp_path / "out.mp4"
    clip.write_bytes(b"")
    monkeypatch.setattr("sys.argv", ["stabilize", str(clip), str(out), "-q"])
    before = signal.signal(signal.SIGTERM, unheard)
    try:
        with pytest.raises(SystemExit) as done:
            main()
        assert signal.getsignal(signal.SIGTERM) is unheard  # put back as it was
    finally:
        signal.signal(signal.SIGTERM, before)
    assert done.value.code == 143
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: terminated (SIGTERM); no output was left half-written under its name"]


def test_sigterm_leaves_no_temporary_file(tmp_path):
    # it ended the process where it stood: a hidden .out.PID.RANDOM.partial.mp4 was left
    clip, out = tmp_path / "long.mp4", tmp_path / "out" / "steady.mp4"
    loop = ["-stream_loop", "3", "-i", str(SAMPLE / "clip.mp4"), "-vf", "scale=320:180"]
    subprocess.run([ffmpeg_exe(), "-v", "error", *loop, str(clip)], check=True)
    job = subprocess.Popen(
        [sys.executable, "-m", "stabilize.cli", str(clip), str(out), "-q"],
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.time() + 120
    while time.time() < deadline and not list(out.parent.glob(".*.partial*")):
        time.sleep(0.05)
    job.send_signal(signal.SIGTERM)
    _, err = job.communicate(timeout=60)
    assert job.returncode == 143 and "error: terminated (SIGTERM)" in err
    assert list(out.parent.iterdir()) == []


def test_the_package_runs_as_the_command():
    # python -m stabilize: "'stabilize' is a package and cannot be directly executed"
    for module in ("stabilize", "stabilize.cli"):
        done = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True)
        assert done.returncode == 0 and done.stdout.decode().startswith("stabilize ")
