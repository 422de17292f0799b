"""Help that teaches: the main job first, choices listed, no placeholders on flags, the
axis letters and the gyro formats explained."""

from __future__ import annotations

import os

import pytest
from typer.testing import CliRunner

from stabilize.cli import app, main
from stabilize.gyro.readers import FORMATS

RUNNER = CliRunner()


def help_text(*command: str) -> str:
    result = RUNNER.invoke(app, [*command, "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0
    return result.output


def test_the_top_level_help_shows_the_main_job_first():
    text = help_text()
    assert text.index("stabilize IN OUT") < text.index("Commands")


def test_flags_have_no_placeholder_and_choices_are_listed():
    text = help_text("run")
    assert "<bool>" not in text
    for choices in ("<dis|raft|raft-large>", "<adaptive|gaussian|lock>", "<auto|dynamic|none>"):
        assert choices in text
    assert "<none|side-by-side>" in text and "<cpu|cuda>" in text


def test_axis_letters_and_gyro_formats_are_explained():
    text = " ".join(help_text("run").split())
    assert "lower case: the negative axis" in text
    assert all(fmt in text for fmt in FORMATS)
    assert ".gcsv, .csv, .txt" in " ".join(help_text("batch").split())


def test_compare_takes_the_run_vocabulary_and_its_old_spellings(monkeypatch, capsys):
    text = help_text("compare")
    for option in ("--gyro-offset", "--gyro-axes", "--gyro-search", "--gyro-timestamps"):
        assert option in text
    assert "--offset" not in text.replace("--gyro-offset", "")  # hidden, still accepted
    monkeypatch.setattr(
        "sys.argv", ["stabilize", "compare", "x.mp4", "--gyro", "g", "--axes", "XYQ"]
    )
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 2 and "--gyro-axes must be three letters" in capsys.readouterr().err


def test_quiet_may_come_first(monkeypatch, capsys):
    monkeypatch.setattr("sys.argv", ["stabilize", "-q", "nope.mp4", "out.mp4"])
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 2
    assert capsys.readouterr().err.strip() == "error: nope.mp4: no such file"


def test_a_pipe_for_the_clip_is_refused_before_it_waits(tmp_path, monkeypatch, capsys):
    # a clip is read in two passes: a FIFO with no writer waited for ever, and a process
    # substitution, <(curl ...), read "not a video FFmpeg can read"
    os.mkfifo(tmp_path / "piped.mp4")
    monkeypatch.setattr("sys.argv", ["stabilize", str(tmp_path / "piped.mp4"), "out.mp4"])
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 2
    assert (
        capsys.readouterr()
        .err.strip()
        .endswith("is a pipe or a device, not a file: save the clip first")
    )


def test_standard_input_for_the_clip_is_named_as_such(monkeypatch, capsys, tmp_path):
    monkeypatch.chdir(tmp_path)  # it read "-: no such file"
    monkeypatch.setattr("sys.argv", ["stabilize", "-", "out.mp4"])
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 2 and "not from standard input" in capsys.readouterr().err


@pytest.mark.parametrize("url", ["https://example.com/clip.mp4", "rtmp://example.com/live"])
def test_a_url_for_the_clip_is_named_as_one(monkeypatch, capsys, url):
    # the path's "//" became "/" and the URL was said to be a missing file
    monkeypatch.setattr("sys.argv", ["stabilize", url, "out.mp4"])
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code == 2
    assert capsys.readouterr().err.strip() == f"error: {url}: a URL: download the clip first"
