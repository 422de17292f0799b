"""Progress bars: one live display for a job's stages, in the order they ran."""

import pytest

from stabilize.cli.bars import batch_progress, progress_bar, with_bars


def two_stages(bar) -> str:
    advance = bar("estimating", 3)
    for _ in range(3):
        advance(1)
    advance = bar("stabilising", 2)
    advance(2)
    return "done"


def test_a_jobs_stages_stand_in_order_a_line_each(capsys):
    # each stage's bar was a display of its own: a log held "stabilising" above
    # "estimating", and a terminal drew both on one line, by turns
    assert with_bars(two_stages) == "done"
    lines = capsys.readouterr().err.splitlines()
    assert [line.split()[0] for line in lines] == ["estimating", "stabilising"]
    assert "3/3" in lines[0] and "2/2" in lines[1]


def test_a_failed_job_leaves_no_bar_above_its_message(capsys):
    def failing(bar) -> None:
        bar("estimating", 3)(1)
        raise RuntimeError("broken")

    with pytest.raises(RuntimeError, match="broken"):
        with_bars(failing)
    assert capsys.readouterr().err == ""  # not even an empty line: the error line is first


def test_quiet_shows_nothing(capsys):
    assert with_bars(two_stages, quiet=True) == "done"
    with progress_bar("evaluating", None, quiet=True) as advance:
        advance(5)
    assert capsys.readouterr().err == ""


def test_a_single_bar_counts_its_units(capsys):
    with progress_bar("rendering", 4) as advance:
        advance(4)
    (line,) = capsys.readouterr().err.splitlines()
    assert line.split()[0] == "rendering" and "4/4" in line


def test_a_failed_batch_leaves_no_bar_above_its_message(capsys):
    # a Ray cluster lost mid-batch: its files bar ended with an empty line above the error
    with pytest.raises(ConnectionError, match="lost"):
        with batch_progress(3) as (file_done, frames_done):
            frames_done(10)
            file_done()
            raise ConnectionError("lost")
    assert capsys.readouterr().err == ""


def test_a_batch_bar_counts_files_and_frames(capsys):
    with batch_progress(2) as (file_done, frames_done):
        frames_done(30)
        file_done()
    (line,) = capsys.readouterr().err.splitlines()
    assert line.split()[0] == "files" and "1/2" in line and "30 frames" in line
