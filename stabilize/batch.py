"""Stabilising a folder of clips: worker processes, a manifest, resume, isolated failures.

Every input gets a row in ``OUT_DIR/manifest.json`` (and ``manifest.csv``): its status
(``done``, ``skipped`` or ``failed``; ``started`` until it ends), seconds, output path,
error, and the key quality figures. The manifest is rewritten after every file, and an
output only ever appears under its final name once complete (the pipeline writes
atomically), so a run that is killed can simply be started again: inputs whose output is
complete and whose size and modification time match the manifest are skipped. A file at
an output's name that the manifest lists as no batch's output is the user's own, and is
left as it is.
"""

from __future__ import annotations

import contextlib
import csv
import ctypes
import hashlib
import json
import multiprocessing as mp
import os
import signal
import time
from collections.abc import Callable, Generator, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from pathlib import Path

from stabilize.gyro.load import find_gyro_log, gyro_settings
from stabilize.gyro.readers import GYRO_SIDECARS, unread_telemetry
from stabilize.video import atomic_output
from stabilize.video.atomic import sweep_stale

MANIFEST = "manifest.json"
BYTES_PER_WORKER = 1.5 * 2**30  # the pipeline's peak at 1080p, with headroom
FRAME_REPORT = 10  # frames a worker counts before it reports them
# a file whose worker died, done again alone, and died again
WORKER_DIED = "its worker process stopped abruptly, running it alone (killed: out of memory?)"
STOPPED = 143  # a worker's exit status once interrupted (128 + SIGTERM)
STOP_GRACE = 10.0  # s a stopped worker has to remove its file's temporary output
THREAD_VARS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS")


@dataclass(frozen=True)
class Job:
    input: str  # relative to the input folder
    source: str  # absolute paths
    output: str
    size: int
    mtime: float
    gyro: str | None = None


# A clip's file, by its suffix (any case): what cameras, phones, camcorders and editors
# write. Without --pattern a folder's photos, sidecars and notes are left out, and so are
# a camera's proxies and thumbnails (GoPro's .LRV and .THM beside each .MP4).
CLIP_SUFFIXES = frozenset(
    {".mp4", ".m4v", ".mov", ".qt", ".mkv", ".webm", ".avi", ".mts", ".m2ts", ".ts"}
    | {".mpg", ".mpeg", ".vob", ".mod", ".tod", ".3gp", ".3g2", ".wmv", ".asf", ".flv"}
    | {".f4v", ".ogv", ".mxf", ".dv", ".y4m"}
)


def find_jobs(
    in_dir: Path,
    out_dir: Path,
    pattern: str | None = None,
    recursive: bool = False,
    gyro_auto: bool = False,
    suffix: str | None = None,
    notify: Callable[[str], None] | None = None,
) -> list[Job]:
    """One job per clip (every file ``pattern`` matches, or, without one, every file
    named as a video: :data:`CLIP_SUFFIXES`), the output mirroring its place in the input
    tree, with the input's suffix (so its container) or ``suffix`` (``--format``).
    ``notify`` hears of the files left out as not named like a video.

    Two inputs that would share an output (``a.mov`` and ``a.mp4`` under ``--format
    mp4``; names that differ only in case, one file on a case-blind disk) each get their
    own: the one whose name it is keeps it, the other's takes its full name
    (``a.mov.mp4``), and ``notify`` hears of it.
    """
    in_dir, out_dir = Path(in_dir).resolve(), Path(out_dir).resolve()
    tell = notify or (lambda _: None)
    jobs, left_out, own_gyro, no_gyro = [], [], [], []
    for path in _files(in_dir, out_dir, pattern or "*", recursive):
        rel = path.relative_to(in_dir)
        if gyro_auto and path.suffix.lower() in GYRO_SIDECARS:
            continue  # a sidecar, not a clip
        if pattern is None and path.suffix.lower() not in CLIP_SUFFIXES:
            left_out.append(rel.as_posix())
            continue
        sidecar = find_gyro_log(path) if gyro_auto else None
        if gyro_auto and sidecar in (None, path):  # a camera's own (a GoPro's), or none
            (own_gyro if sidecar else no_gyro).append(rel.as_posix())
        stat = path.stat()
        jobs.append(
            Job(
                str(rel),
                str(path),
                str(out_dir / (rel.with_suffix(suffix) if suffix else rel)),
                stat.st_size,
                stat.st_mtime,
                str(sidecar) if sidecar else None,
            )
        )
    if left_out:
        tell(
            f"{len(left_out)} file(s) not named as videos left out ({_few(left_out)}); "
            "--pattern '*' takes every file"
        )
    if own_gyro:
        tell(f"{len(own_gyro)} clip(s) stabilised from the gyro their camera recorded in "
             f"them ({_few(own_gyro)})")  # fmt: skip
    if no_gyro:
        tell(f"{len(no_gyro)} clip(s) with no gyro log beside them or in them, stabilised "
             f"from their video ({_few(no_gyro)}){unread_telemetry()}")  # fmt: skip
    return _distinct_outputs(jobs, tell)


def _few(names: list[str]) -> str:
    """The first three of ``names``, and an ellipsis for the rest."""
    return ", ".join(names[:3]) + (", …" if len(names) > 3 else "")


def _files(in_dir: Path, out_dir: Path, pattern: str, recursive: bool) -> list[Path]:
    """The files under ``in_dir`` that ``pattern`` matches, in order, but for hidden ones
    and those in ``out_dir``."""
    paths = in_dir.rglob(pattern) if recursive else in_dir.glob(pattern)
    return [
        path
        for path in sorted(p for p in paths if p.is_file())
        if out_dir not in path.parents and not path.name.startswith(".")
    ]


def _distinct_outputs(jobs: list[Job], notify: Callable[[str], None]) -> list[Job]:
    """``jobs`` with no output shared, compared case-blind (see :func:`find_jobs`);
    a clash left after renaming (an input itself named ``a.mov.mp4``) is refused."""
    taken: dict[str, Job] = {}
    outputs: dict[str, str] = {}
    # first those whose output is named as their input: they keep that name
    for job in sorted(jobs, key=lambda j: Path(j.output).name != Path(j.input).name):
        output = Path(job.output)
        if (first := taken.get(str(output).casefold())) is not None:
            renamed = output.with_name(Path(job.input).name + output.suffix)
            if str(renamed).casefold() in taken:
                raise ValueError(
                    f"{first.input} and {job.input} would both be written as {output}, "
                    f"and {renamed} is taken too: rename one, or pick with --pattern"
                )
            notify(
                f"{first.input} and {job.input} would both be written as "
                f"{Path(outputs[first.input]).name}: "
                f"{job.input} goes to {renamed.name}"
            )
            output = renamed
        taken[str(output).casefold()] = job
        outputs[job.input] = str(output)
    return [replace(job, output=outputs[job.input]) for job in jobs]


def load_manifest(out_dir: Path) -> dict[str, dict]:
    path = Path(out_dir) / MANIFEST
    if not path.is_file():
        return {}
    try:
        rows = json.loads(path.read_text())
    except json.JSONDecodeError:
        return {}  # a damaged manifest: redo everything rather than trust it
    return {row["input"]: row for row in rows}


def write_manifest(out_dir: Path, rows: dict[str, dict]) -> None:
    out_dir = Path(out_dir)
    ordered = [rows[k] for k in sorted(rows)]
    with atomic_output(out_dir / MANIFEST, overwrite=True) as tmp:
        tmp.write_text(json.dumps(ordered, indent=2))
    fields = [
        "input",
        "status",
        "seconds",
        "output",
        "error",
        "mean_support",
        "zoom",
        "cropping_ratio",
        "frames",
        "peak_mb",
        "notices",
    ]
    with atomic_output(out_dir / "manifest.csv", overwrite=True) as tmp:
        # a name that is not UTF-8 (caf\xe9.mp4 off an old card) as its own bytes: it
        # failed the batch ("surrogates not allowed"); the JSON escapes it
        with open(tmp, "w", newline="", errors="surrogateescape") as f:
            writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
            writer.writeheader()
            writer.writerows({**r, "notices": " | ".join(r.get("notices", ()))} for r in ordered)


def is_complete(job: Job, row: dict | None, key: str = "") -> bool:
    """Done before, from this very input, with the same settings (``key``), and the
    output is still there."""
    return (
        row is not None
        and row.get("status") in ("done", "skipped")
        and row.get("size") == job.size
        and row.get("mtime") == job.mtime
        and row.get("settings") == key
        and Path(job.output).is_file()
    )


def settings_key(settings) -> str:
    """A short hash of every setting that shapes an output (not the encoder's threads,
    which a batch sets itself per worker)."""
    from stabilize.pipeline import settings_summary

    summary = settings_summary(settings)
    summary["encoding"].pop("threads", None)
    text = json.dumps(summary, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


_FRAMES = None  # a worker's queue for frame counts, set by _start_worker


def _start_worker(threads: int, frames) -> None:
    """Bound each worker's threads (numba, BLAS, OpenCV), so N workers share the cores,
    and keep the queue that frame counts go back on. SIGTERM (the batch stopping it)
    interrupts its file as Ctrl-C does (:func:`_pooled_job`)."""
    global _FRAMES
    _FRAMES = frames
    signal.signal(signal.SIGTERM, _interrupt)
    os.setpgrp()  # a group of its own, with its FFmpeg processes: stopped together
    _end_with_parent()
    for var in THREAD_VARS:
        os.environ[var] = str(threads)
    import cv2

    cv2.setNumThreads(threads)


PR_SET_PDEATHSIG = 1  # Linux's prctl option: a signal for when the parent ends


def _end_with_parent() -> None:
    """SIGTERM to this worker when the batch ends, however it ends (SIGKILL included),
    now that a signal to the batch's process group no longer reaches it (Linux; where
    there is no prctl, a worker ends once its file is done and it finds the batch gone)."""
    parent = os.getppid()
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != parent:  # it ended before the request was made
        os.kill(os.getpid(), signal.SIGTERM)


def _interrupt(_signum: int, _frame) -> None:
    raise KeyboardInterrupt


def _pooled_job(job: Job, settings) -> dict:
    """:func:`run_job` in a pool's worker, which an interrupt (Ctrl-C, or the batch
    stopping it) ends once its file's temporary output is removed: the pool's own loop
    took it for the job's failure and went on with the next file."""
    try:
        return run_job(job, settings)
    except KeyboardInterrupt:
        # with any FFmpeg an interrupt left running (one that struck while it started
        # wrote its file after the job had removed it): the worker leads its own group
        with contextlib.suppress(OSError):
            os.killpg(os.getpid(), signal.SIGKILL)
        os._exit(STOPPED)


def _report_frames(n: int) -> None:
    if _FRAMES is not None:
        _FRAMES.put(n)


def run_job(job: Job, settings, on_frames: Callable[[int], None] | None = None) -> dict:
    """Stabilise one file; never raises: a failure is a row with its error.

    ``on_frames(n)`` hears of every n frames written (a worker reports on its queue).
    """
    from stabilize.pipeline import COMPILING, stabilize_video

    on_frames = on_frames or _report_frames
    counted = [0]

    def stage(label: str, _total: int | None):
        if label != "stabilising":
            return lambda n=1: None

        def advance(n: int = 1) -> None:  # batched: one message per FRAME_REPORT frames
            counted[0] += n
            if counted[0] >= FRAME_REPORT:
                on_frames(counted[0])
                counted[0] = 0

        return advance

    start = time.perf_counter()
    row = job_row(job)
    row["settings"] = settings_key(settings)
    notices: list[str] = []  # what the file's run would say (they were lost in a batch)
    row["notices"] = notices

    def note(message: str) -> None:
        if not message.startswith(COMPILING):  # the batch's, said once: not of this file
            notices.append(message)

    try:
        if job.gyro:
            settings = replace(settings, **gyro_settings(Path(job.gyro), Path(job.source)))
        summary, _ = stabilize_video(
            job.source, job.output, settings, overwrite=True, progress=stage, notify=note
        )
        row.update(
            status="done",
            error="",
            frames=summary["frames"],
            zoom=summary["zoom"],
            cropping_ratio=summary["cropping_ratio"],
            mean_support=summary["mean_support"],
        )
    except Exception as err:  # isolate every failure: one bad file must not stop the rest
        message = str(err).splitlines()[0] if str(err) else type(err).__name__
        row.update(status="failed", error=message)
    if counted[0]:
        on_frames(counted[0])
    row["seconds"] = round(time.perf_counter() - start, 3)
    row["peak_mb"] = peak_memory_mb()
    return row


def peak_memory_mb() -> float:
    """Peak resident memory so far of this process and of its largest finished child
    (FFmpeg), MB: what one worker needs."""
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    child = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return round(max(own, child) / 1024.0, 1)  # Linux reports KiB


def default_workers() -> int:
    """One per core, as long as memory allows a 1080p clip each."""
    cores = os.cpu_count() or 1
    try:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError):
        return cores
    return max(1, min(cores, int(memory // BYTES_PER_WORKER)))


def run_batch(
    jobs: list[Job],
    out_dir: Path,
    settings,
    workers: int | None = None,
    on_done: Callable[[dict], None] | None = None,
    ray_address: str | None = None,
    on_frames: Callable[[int], None] | None = None,
    *,
    force: bool = False,
) -> list[dict]:
    """Run the jobs not already complete (all of them with ``force``); returns every
    job's row, in input order. A job counts as complete when the same input was done
    with the same settings (a hash of them is kept in the manifest). A job whose output
    name holds a file that no batch wrote there (the manifest lists no such output) is
    left undone, a failed row, the file as it is (``force`` replaces it).

    ``on_done(row)`` hears of every file as it finishes, ``on_frames(n)`` of frames
    written (local workers; Ray tasks report files only).

    With ``ray_address`` (an address, or ``auto`` for the running cluster) the jobs run
    as Ray tasks instead of local processes; the manifest and resume work the same.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    sweep_stale(out_dir, recursive=True)  # a killed run's leftovers, never a running one's
    previous = load_manifest(out_dir)
    key = settings_key(settings)
    ours = {row.get("output") for row in previous.values() if not row.get("foreign")}
    rows: dict[str, dict] = {}
    todo = []
    for job in jobs:
        if not force and is_complete(job, previous.get(job.input), key):
            rows[job.input] = {**previous[job.input], "status": "skipped", "seconds": 0.0}
        elif not force and job.output not in ours and os.path.lexists(job.output):
            rows[job.input] = _foreign(job)
        else:
            todo.append(job)
            continue
        if on_done:
            on_done(rows[job.input])
    # the outputs claimed before any is written: a run killed after an output's rename
    # and before its row leaves it a row, "started", so it is never taken for a stranger's
    started = {job.input: job_row(job, status="started", error="") for job in todo}
    write_manifest(out_dir, {**previous, **started, **rows})
    rows_in = (
        _execute_ray(todo, settings, ray_address)
        if ray_address
        else _execute(todo, settings, workers or default_workers(), on_frames)
    )
    try:
        for row in rows_in:
            rows[row["input"]] = row
            write_manifest(out_dir, {**previous, **started, **rows})
            if on_done:
                on_done(row)
    except BaseException:  # stopped: what its stopped workers left, once they are gone
        sweep_stale(out_dir, recursive=True)
        raise
    return [rows[job.input] for job in jobs]


def job_row(job: Job, **fields) -> dict:
    """A job's manifest row: what it reads and writes, and ``fields``."""
    return {"input": job.input, "output": job.output, "size": job.size, "mtime": job.mtime} | fields


def _foreign(job: Job) -> dict:
    """The row of a job whose output's name holds a file this folder's batches did not
    write (the manifest lists none there): left as it is, unless ``--force``."""
    error = f"{job.output} is there already, and not from a batch (--force replaces it)"
    return job_row(job, status="failed", error=error, seconds=0.0, foreign=True)


def _execute(
    jobs: list[Job], settings, workers: int, on_frames: Callable[[int], None] | None
) -> Iterator[dict]:
    """The jobs' rows as they finish: in this process with one worker, else in a pool
    of worker processes. A worker that dies (the kernel's out-of-memory killer's usual
    victim) broke the pool, and the batch ended with it, every file in flight lost: the
    files it left unfinished are done again one at a time, and one whose worker dies
    with it alone fails."""
    on_frames = on_frames or (lambda n: None)
    if workers <= 1 or len(jobs) <= 1:
        for job in jobs:
            yield run_job(job, settings, on_frames)
        return
    while jobs:
        unfinished = yield from _pooled(jobs, settings, workers, on_frames)
        if unfinished and workers == 1:  # alone, and in order: the first was running
            yield job_row(unfinished[0], status="failed", error=WORKER_DIED, seconds=0.0)
            unfinished = unfinished[1:]
        jobs, workers = unfinished, 1


def _pooled(
    jobs: list[Job], settings, workers: int, on_frames: Callable[[int], None]
) -> Generator[dict, None, list[Job]]:
    """The rows of ``jobs`` run by ``workers`` processes, as they finish; returns the
    jobs a dead worker left unfinished (in ``jobs``' order), none if none died."""
    threads = max(1, (os.cpu_count() or 1) // workers)
    settings = replace(settings, encoding=replace(settings.encoding, threads=threads))
    context = mp.get_context("spawn")  # clean workers: no inherited threads or locks
    frames = context.SimpleQueue()
    unfinished: list[Job] = []
    with ProcessPoolExecutor(
        workers, mp_context=context, initializer=_start_worker, initargs=(threads, frames)
    ) as pool:
        futures = {pool.submit(_pooled_job, job, settings): job for job in jobs}
        pending = set(futures)
        try:
            while pending:
                finished, pending = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
                while not frames.empty():
                    on_frames(frames.get())
                for future in finished:
                    if isinstance(future.exception(), BrokenProcessPool):
                        unfinished.append(futures[future])
                    else:
                        yield future.result()
        except BaseException:  # Ctrl-C, SIGTERM: the pool's exit ran every queued file
            _stop(pool)
            raise
        while not frames.empty():
            on_frames(frames.get())
    return sorted(unfinished, key=jobs.index)


def _stop(pool: ProcessPoolExecutor, grace: float = STOP_GRACE) -> None:
    """Stop a pool now: no queued file started, and each worker's file interrupted (its
    temporary output removed), the worker killed if it has not ended in ``grace`` s.
    Without this, Ctrl-C waited for every queued file (31 s for 2 of 4 one-minute clips
    here; hours for a large folder), and SIGTERM left the workers going on."""
    pool.shutdown(wait=False, cancel_futures=True)
    workers = [p for p in mp.active_children() if p.is_alive()]
    for worker in workers:
        worker.terminate()  # SIGTERM: interrupted as by Ctrl-C (_start_worker)
    deadline = time.monotonic() + grace
    for worker in workers:
        worker.join(max(deadline - time.monotonic(), 0.0))
        if worker.is_alive():
            worker.kill()
            worker.join()


def _execute_ray(jobs: list[Job], settings, address: str) -> Iterator[dict]:
    """The jobs as Ray tasks, one CPU and one thread each; rows as tasks finish.

    Every node must see the input and output paths (a shared file system) and have this
    package installed.
    """
    try:
        import ray
    except ImportError:
        raise RuntimeError(
            "--ray needs the 'cluster' extra: pip install 'hough-stabilize[cluster]'"
        ) from None
    if not ray.is_initialized():
        ray.init(address=address, log_to_driver=False)
    single = dict.fromkeys(THREAD_VARS, "1")
    task = ray.remote(num_cpus=1, runtime_env={"env_vars": single})(run_job)
    settings = replace(settings, encoding=replace(settings.encoding, threads=1))
    tasks = {task.remote(job, settings): job for job in jobs}
    pending = list(tasks)
    while pending:
        (ready,), pending = ray.wait(pending, num_returns=1)
        try:
            row = ray.get(ready)
        except Exception as err:  # its worker died (out of memory), or its node did
            message = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
            row = job_row(tasks[ready], status="failed", error=f"its Ray task failed: {message}")
        yield row


__all__ = ["CLIP_SUFFIXES", "Job", "find_jobs", "load_manifest", "run_batch"]
