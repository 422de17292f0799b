"""How every command ends when it fails: one ``error:`` line and a status, never a
traceback (unless asked for)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stabilize.cli import main
from stabilize.cli.app import LONGEST, one_line


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
