"""Outputs appear whole or not at all; a killed run's leftovers are swept, a running
one's are not."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from stabilize.video import atomic_output
from stabilize.video.atomic import sweep_stale


def dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_dead_runs_leftover_is_swept_and_a_live_ones_kept(tmp_path):
    dead = tmp_path / f".out.{dead_pid()}.abcd1234.partial.mp4"
    live = tmp_path / f".out.{os.getpid()}.efgh5678.partial.mp4"
    other = tmp_path / f".other.{dead_pid()}.ijkl9012.partial.mp4"
    for path in (dead, live, other):
        path.write_bytes(b"half a video")
    with atomic_output(tmp_path / "out.mp4") as tmp:
        assert f".{os.getpid()}." in tmp.name
        tmp.write_bytes(b"video")
    assert not dead.exists() and live.exists() and other.exists()  # only its own name
    assert (tmp_path / "out.mp4").read_bytes() == b"video"
    assert sweep_stale(tmp_path) == 1 and not other.exists() and live.exists()


def test_a_failed_block_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError), atomic_output(tmp_path / "out.mp4") as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("encoder died")
    assert list(tmp_path.iterdir()) == []


def test_an_image_sequence_is_moved_in_whole_replacing_the_old_one(tmp_path):
    pattern = tmp_path / "frames" / "f%03d.png"
    dead = tmp_path / "frames" / f".f03d.{dead_pid()}.abcd1234.partial"
    dead.mkdir(parents=True)
    (dead / "f001.png").write_bytes(b"half")
    old = [tmp_path / "frames" / f"f{n:03d}.png" for n in (1, 2, 3)]
    for path in old:
        path.write_bytes(b"old")
    with pytest.raises(FileExistsError, match="3 pictures of this sequence exist"):
        with atomic_output(pattern):
            pass
    with atomic_output(pattern, overwrite=True) as tmp:
        assert "%" not in str(tmp.parent)  # FFmpeg reads any % as the number's place
        for n in (1, 2):
            (tmp.parent / tmp.name.replace("%03d", f"{n:03d}")).write_bytes(b"new")
    names = sorted(p.name for p in (tmp_path / "frames").iterdir())
    assert names == ["f001.png", "f002.png"]  # the old third, and the dead run's folder, gone
    assert old[0].read_bytes() == b"new"


def test_a_failed_image_sequence_leaves_the_old_one(tmp_path):
    old = tmp_path / "f1.png"
    old.write_bytes(b"old")
    with pytest.raises(RuntimeError), atomic_output(tmp_path / "f%d.png", overwrite=True) as tmp:
        (tmp.parent / "f1.png").write_bytes(b"half")
        raise RuntimeError("encoder died")
    assert [p.name for p in tmp_path.iterdir()] == ["f1.png"] and old.read_bytes() == b"old"


def test_a_report_folder_gets_its_files_whole_or_keeps_the_old_ones(tmp_path):
    # a report's files were written in place: a failed run left some new, some old
    from stabilize.video.atomic import atomic_folder

    report = tmp_path / "report"
    with atomic_folder(report) as tmp:
        for name in ("summary.json", "path.csv"):
            (tmp / name).write_text("first")
    with pytest.raises(RuntimeError), atomic_folder(report) as tmp:
        (tmp / "summary.json").write_text("second")
        raise RuntimeError("the plot failed")
    assert {p.name: p.read_text() for p in report.iterdir()} == {
        "summary.json": "first",
        "path.csv": "first",
    }
    assert [p.name for p in tmp_path.iterdir()] == ["report"]  # no temporary folder left


def test_a_name_near_the_longest_a_folder_holds_gets_a_temporary_name_beside_it(tmp_path):
    # ".NAME.PID.RANDOM.partial.mp4" of a 249-character name: "File name too long",
    # once all the work was done
    final = tmp_path / ("é" * 120 + ".mp4")  # 244 bytes
    with atomic_output(final) as tmp:
        assert len(tmp.name.encode()) <= 255
        tmp.write_bytes(b"video")
    assert final.read_bytes() == b"video"


@pytest.mark.parametrize("overwrite", [False, True])
def test_a_pipe_at_the_outputs_name_is_never_replaced(tmp_path, overwrite):
    # the final rename made a FIFO (or a device node, /dev/null's twin) a plain file
    fifo = tmp_path / "out.mp4"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match=r"out\.mp4 is a pipe or a device, not a file"):
        with atomic_output(fifo, overwrite=overwrite) as tmp:
            tmp.write_bytes(b"video")
    assert fifo.is_fifo() and os.listdir(tmp_path) == ["out.mp4"]
