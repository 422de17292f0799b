"""Folders: isolated failures, the manifest, resume, and a killed run."""

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from stabilize.batch import find_jobs
from stabilize.cli import app
from stabilize.video import ffmpeg_exe
from tests.stabilize.helpers import SAMPLE as SAMPLE_DIR

SAMPLE = SAMPLE_DIR / "clip.mp4"


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def clip(tmp_path_factory) -> bytes:
    """The sample's first 1.5 s at 320×180 (45 frames, its audio): a batch's tests run a
    few minutes less than at its 640×360, and 8 s less than on all 90 frames."""
    out = tmp_path_factory.mktemp("small") / "clip.mp4"
    first = ["-i", str(SAMPLE), "-t", "1.5", "-vf", "scale=320:180", "-c:a", "copy"]
    subprocess.run([ffmpeg_exe(), "-v", "error", *first, str(out)], check=True)
    return out.read_bytes()


@pytest.fixture
def folder(tmp_path, clip) -> Path:
    src = tmp_path / "in"
    (src / "day2").mkdir(parents=True)
    (src / "a.mp4").write_bytes(clip)
    (src / "day2" / "b.mp4").write_bytes(clip)
    (src / "corrupt.mp4").write_bytes(clip[: len(clip) // 6])
    (src / "notes.mov").write_text("not a video\n")
    return src


def test_a_folder_with_bad_files(folder, tmp_path):
    before = {p: digest(p) for p in folder.rglob("*") if p.is_file()}
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app, ["batch", str(folder), str(out), "--recursive", "--workers", "2", "-q"]
    )
    assert result.exit_code == 1
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*.mp4")) == [
        "a.mp4",
        "day2/b.mp4",
    ]
    rows = {r["input"]: r for r in json.loads((out / "manifest.json").read_text())}
    assert [rows[k]["status"] for k in sorted(rows)] == ["done", "failed", "done", "failed"]
    assert rows["corrupt.mp4"]["error"] and rows["notes.mov"]["error"]
    assert 1 / rows["a.mp4"]["zoom"] <= rows["a.mp4"]["cropping_ratio"] < 1  # as the run's
    assert (out / "manifest.csv").read_text().count("\n") == 5
    assert {p: digest(p) for p in before} == before  # every input untouched

    again = CliRunner().invoke(app, ["batch", str(folder), str(out), "--recursive", "-q"])
    rows = {r["input"]: r for r in json.loads((out / "manifest.json").read_text())}
    assert again.exit_code == 1
    assert rows["a.mp4"]["status"] == rows["day2/b.mp4"]["status"] == "skipped"


def test_a_changed_input_is_done_again(folder, tmp_path):
    out = tmp_path / "out"
    CliRunner().invoke(app, ["batch", str(folder), str(out), "--pattern", "a.mp4", "-q"])
    os.utime(folder / "a.mp4", (time.time() + 10, time.time() + 10))
    CliRunner().invoke(app, ["batch", str(folder), str(out), "--pattern", "a.mp4", "-q"])
    rows = json.loads((out / "manifest.json").read_text())
    assert rows[0]["status"] == "done"


def test_changed_settings_or_force_redo_a_file_and_format_converts(folder, tmp_path):
    out = tmp_path / "out"
    base = ["batch", str(folder), str(out), "--pattern", "a.mp4", "-q"]

    def status(*extra: str) -> str:
        result = CliRunner().invoke(app, [*base, *extra])
        assert result.exit_code == 0, result.output
        rows = json.loads((out / "manifest.json").read_text())
        return next(r["status"] for r in rows if r["input"] == "a.mp4")

    assert status() == "done"
    assert status() == "skipped"  # the same settings: resumed
    assert status("--smooth", "1.0") == "done"  # other settings: done again
    assert status("--smooth", "1.0") == "skipped"
    assert status("--smooth", "1.0", "--force") == "done"
    assert status("--smooth", "1.0", "--format", "mkv") == "done"
    assert (out / "a.mkv").is_file() and probe_muxer(out / "a.mkv") == "matroska"


def probe_muxer(path: Path) -> str:
    import av

    with av.open(str(path)) as c:
        return c.format.name.split(",")[0]


def test_gyro_sidecars_are_found_and_not_taken_for_clips(folder, tmp_path):
    (folder / "a.gcsv").write_text("GYROFLOW IMU LOG\n")
    jobs = {j.input: j for j in find_jobs(folder, tmp_path / "out", gyro_auto=True)}
    assert jobs["a.mp4"].gyro.endswith("a.gcsv") and "a.gcsv" not in jobs


def test_with_no_log_beside_it_a_cameras_own_gyro_is_taken(folder, tmp_path, shared):
    # a GoPro's clips carry their gyro: --gyro auto stabilised them from their video alone
    (folder / "gopro.mp4").write_bytes((shared / "data" / "gopro" / "karma.mp4").read_bytes())
    said: list[str] = []
    jobs = {
        j.input: j for j in find_jobs(folder, tmp_path / "out", gyro_auto=True, notify=said.append)
    }
    assert jobs["gopro.mp4"].gyro == jobs["gopro.mp4"].source and jobs["a.mp4"].gyro is None
    assert "1 clip(s) stabilised from the gyro their camera recorded in them (gopro.mp4)" in said
    assert any("clip(s) with no gyro log beside them or in them" in n for n in said)


def test_each_files_notices_are_kept_in_the_manifest(folder, tmp_path):
    # a batch's files said nothing of what was changed or left out, where run says it
    out = tmp_path / "out"
    args = ["batch", str(folder), str(out), "--pattern", "a.mp4", "--format", "avi"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "notice: audio #1: aac → libmp3lame for AVI" in result.output
    row = json.loads((out / "manifest.json").read_text())[0]
    assert "audio #1: aac → libmp3lame for AVI" in row["notices"]
    assert "audio #1: aac → libmp3lame for AVI" in (out / "manifest.csv").read_text()


def test_a_files_notices_leave_out_the_batchs_own(folder, tmp_path, monkeypatch):
    # the first file of each worker listed "compiling the estimator's kernels", which the
    # batch says once for all of them
    import stabilize.batch as batch
    import stabilize.pipeline as pipeline
    from stabilize import Settings

    said = f"{pipeline.COMPILING}: about 15 s, once"
    monkeypatch.setattr(pipeline, "compiling_notice", lambda: (said,))
    (job,) = find_jobs(folder, tmp_path / "out", "a.mp4")
    row = batch.run_job(job, Settings(), lambda n: None)
    assert row["status"] == "done" and row["notices"]  # the file's own are kept
    assert not any(n.startswith(pipeline.COMPILING) for n in row["notices"])


def test_a_killed_run_leaves_nothing_unfinished_under_a_final_name(folder, tmp_path):
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "stabilize.cli",
            "batch",
            str(folder),
            str(out),
            "--recursive",
            "--workers",
            "1",
            "-q",
        ],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.time() + 120
    while time.time() < deadline and not list(out.rglob(".*.partial*")):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    done = set()
    if (out / "manifest.json").is_file():
        done = {
            r["output"]
            for r in json.loads((out / "manifest.json").read_text())
            if r["status"] in ("done", "skipped")
        }
    finals = {str(p) for p in out.rglob("*.mp4") if not p.name.startswith(".")}
    assert finals <= done  # any file under a final name is one the manifest calls done
    result = CliRunner().invoke(app, ["batch", str(folder), str(out), "--recursive", "-q"])
    assert result.exit_code == 1  # resumes, and only the two bad files fail
    assert not list(out.rglob(".*.partial*"))
    assert len(list(out.rglob("*.mp4"))) == 2


@pytest.mark.parametrize("workers", [1, 2])
def test_frames_written_are_reported_from_every_worker(folder, tmp_path, workers):
    from stabilize import Settings
    from stabilize.batch import run_batch

    jobs = [j for j in find_jobs(folder, tmp_path / "out", "*", True) if "corrupt" not in j.input]
    jobs = [j for j in jobs if j.input.endswith(".mp4")]
    frames, files = [], []
    run_batch(jobs, tmp_path / "out", Settings(), workers, files.append, on_frames=frames.append)
    assert len(files) == 2 and sum(frames) == 2 * 45


def test_only_videos_are_taken_and_the_rest_is_named(folder, tmp_path):
    for name in ("photo.JPG", "GX010001.LRV", "GX010001.THM", "IMG_1.AAE"):
        (folder / name).write_bytes(b"x")
    (folder / "b.MTS").write_bytes(b"x")
    heard: list[str] = []
    jobs = find_jobs(folder, tmp_path / "out", notify=heard.append)
    assert [j.input for j in jobs] == ["a.mp4", "b.MTS", "corrupt.mp4", "notes.mov"]
    assert heard == [
        "4 file(s) not named as videos left out (GX010001.LRV, GX010001.THM, IMG_1.AAE, …); "
        "--pattern '*' takes every file"
    ]
    assert len(find_jobs(folder, tmp_path / "out", "*")) == 8  # a pattern takes what it names


def test_two_inputs_never_share_an_output(folder, tmp_path):
    # a.mov and a.mp4 under --format mp4: the second was written over the first, and
    # both rows read "done"
    (folder / "a.mov").write_bytes(b"x")
    (folder / "A.MP4").write_bytes(b"x")
    heard: list[str] = []
    jobs = find_jobs(folder, tmp_path / "out", suffix=".mp4", notify=heard.append)
    outputs = {j.input: Path(j.output).name for j in jobs}
    assert outputs == {
        "A.MP4": "A.MP4.mp4",  # a case-blind disk holds one of A.mp4 and a.mp4
        "a.mov": "a.mov.mp4",
        "a.mp4": "a.mp4",
        "corrupt.mp4": "corrupt.mp4",
        "notes.mov": "notes.mp4",
    }
    assert "a.mp4 and a.mov would both be written as a.mp4: a.mov goes to a.mov.mp4" in heard
    (folder / "a.mov.mp4").write_bytes(b"x")  # its renaming is taken too: refused
    with pytest.raises(ValueError, match="taken too"):
        find_jobs(folder, tmp_path / "out", suffix=".mp4")


def test_a_file_no_batch_wrote_is_left_as_it_is(folder, tmp_path):
    from stabilize import Settings
    from stabilize.batch import run_batch

    out = tmp_path / "out"
    out.mkdir()
    (out / "corrupt.mp4").write_text("the user's own\n")
    jobs = find_jobs(folder, out, "corrupt.mp4")
    for _ in range(2):  # and again on a rerun, though the manifest now names it
        (row,) = run_batch(jobs, out, Settings())
        assert row["status"] == "failed" and "--force replaces it" in row["error"]
        assert (out / "corrupt.mp4").read_text() == "the user's own\n"
    (row,) = run_batch(jobs, out, Settings(), force=True)  # tried, so the input's error
    assert "not from a batch" not in row["error"] and "corrupt.mp4" in row["error"]


def test_an_output_a_killed_run_wrote_is_still_its_own(folder, tmp_path, monkeypatch):
    import stabilize.batch as batch
    from stabilize import Settings

    out = tmp_path / "out"
    jobs = find_jobs(folder, out, "corrupt.mp4")

    def killed_after_the_rename(todo, *_):
        Path(todo[0].output).write_text("made\n")
        raise KeyboardInterrupt  # before the row that says so
        yield

    monkeypatch.setattr(batch, "_execute", killed_after_the_rename)
    with pytest.raises(KeyboardInterrupt):
        batch.run_batch(jobs, out, Settings())
    rows = json.loads((out / "manifest.json").read_text())
    assert [r["status"] for r in rows] == ["started"]
    monkeypatch.undo()
    (row,) = batch.run_batch(jobs, out, Settings())
    assert "not from a batch" not in row["error"]  # done again, not taken for a stranger's


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["TERM", "KILL"])
def test_a_stopped_batch_stops_its_workers_and_starts_no_queued_file(tmp_path, signum):
    # SIGTERM ended the batch where it stood, its workers going on with their files, and
    # Ctrl-C waited for every queued file (31 s for 2 of 4 one-minute clips); both stop
    # it by the same way out (batch._stop), SIGTERM here, as `kill` sends it to the batch
    # alone. SIGKILL, which nothing catches, left the workers going on too
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    loop = ["-stream_loop", "1", "-i", str(SAMPLE), "-vf", "scale=320:180"]
    subprocess.run([ffmpeg_exe(), "-v", "error", *loop, str(src / "a.mp4")], check=True)
    for name in ("b.mp4", "c.mp4", "d.mp4"):
        (src / name).write_bytes((src / "a.mp4").read_bytes())
    job = subprocess.Popen(
        [sys.executable, "-m", "stabilize.cli", "batch", str(src), str(out), "--workers", "2"],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.time() + 120
    while time.time() < deadline and not list(out.glob(".*.partial*")):
        time.sleep(0.05)
    job.send_signal(signum)
    _, err = job.communicate(timeout=60)
    if signum == signal.SIGTERM:
        assert job.returncode == 143 and err.splitlines()[-1].startswith("error: terminated")
    else:
        assert job.returncode == -signal.SIGKILL  # no word: it could say none
    manifests = ["manifest.csv", "manifest.json"]
    # a stopped worker removes its temporary output at once, but on a loaded machine (the
    # whole suite on 2 cores) it may take a moment to run; one left going never would
    deadline = time.time() + 30
    while time.time() < deadline and sorted(p.name for p in out.iterdir()) != manifests:
        time.sleep(0.1)
    time.sleep(3)  # what a worker left going would write meanwhile
    assert sorted(p.name for p in out.iterdir()) == manifests
    rows = json.loads((out / "manifest.json").read_text())
    assert {r["status"] for r in rows} == {"started"}  # all done again by the next run


def test_a_worker_that_dies_costs_its_file_alone(folder, tmp_path, clip):
    # a worker killed (the out-of-memory killer's way) broke the pool: the batch ended,
    # "A process in the process pool was terminated abruptly", every file in flight lost
    import multiprocessing as mp

    import stabilize.batch as batch
    from stabilize import Settings

    for name in ("b.mp4", "c.mp4"):
        (folder / name).write_bytes(clip)
    jobs = find_jobs(folder, tmp_path / "out", "[abc].mp4")
    kills: list[int] = []
    seen: set[int] = set()  # the pool's workers at a kill: the next kill is in a new pool

    def kill_a_worker(_frames: int) -> None:  # in the pool, then again when alone
        workers = [w for w in mp.active_children() if w.pid not in seen]
        if len(kills) < 2 and workers:
            seen.update(w.pid for w in mp.active_children())
            os.kill(workers[0].pid, signal.SIGKILL)
            kills.append(workers[0].pid)

    rows = list(batch._execute(jobs, Settings(), 2, kill_a_worker))
    assert len(kills) == 2 and sorted(r["input"] for r in rows) == ["a.mp4", "b.mp4", "c.mp4"]
    failed = [r for r in rows if r["status"] == "failed"]
    assert len(failed) == 1 and failed[0]["error"] == batch.WORKER_DIED
    assert all(Path(r["output"]).is_file() for r in rows if r["status"] == "done")


def test_a_name_that_is_not_utf8_is_done_and_listed(tmp_path, clip):
    # caf\xe9.mp4 (Latin-1, off an old card): the manifest's CSV failed the whole batch,
    # "internal error (UnicodeEncodeError: ... surrogates not allowed)"
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    name = os.fsdecode(b"caf\xe9.mp4")
    (src / name).write_bytes(clip)
    result = CliRunner().invoke(app, ["batch", str(src), str(out), "-q"])
    assert result.exit_code == 0, result.output
    (row,) = json.loads((out / "manifest.json").read_text())
    assert row["input"] == name and row["status"] == "done" and (out / name).is_file()
    assert b"caf\xe9.mp4,done" in (out / "manifest.csv").read_bytes()  # its own bytes
