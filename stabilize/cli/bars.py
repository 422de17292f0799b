"""Progress bars for long work: rich on stderr, silent with --quiet."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator
from typing import TypeVar

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from stabilize.progress import ProgressFactory

T = TypeVar("T")


def _stage_columns() -> tuple:
    return (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[rate]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )


@contextlib.contextmanager
def stage_bars(*, quiet: bool = False) -> Iterator[Callable[..., Callable[[int], None]]]:
    """Yields ``bar(label, total, unit="frames")``, which adds a stage's bar below the last
    one and returns its ``advance(n)`` (rate in units/s, and ETA, on stderr).

    One live display holds every stage's bar: each stage's own display, on a console of
    its own, drew over the last one's line, so a terminal's bar flickered between
    "estimating" and "stabilising", and a log held them in reverse order. The bars stay
    when the job ends; a failure clears them, leaving nothing above its message."""
    if quiet:
        yield lambda label, total, unit="frames": lambda n=1: None
        return
    with Progress(*_stage_columns(), console=Console(stderr=True), transient=False) as progress:

        def bar(label: str, total: int | None, unit: str = "frames") -> Callable[[int], None]:
            task = progress.add_task(label, total=total, rate="")

            def advance(n: int = 1) -> None:
                progress.advance(task, n)
                speed = next(t.speed for t in progress.tasks if t.id == task)
                if speed:
                    progress.update(task, rate=f"{speed:.1f} {unit}/s")

            return advance

        with _cleared_on_failure(progress):
            yield bar


@contextlib.contextmanager
def _cleared_on_failure(progress: Progress) -> Iterator[None]:
    """A failure inside clears ``progress``' bars, leaving nothing above its message."""
    try:
        yield
    except BaseException:
        progress.live.transient = True
        # rich ends a display on a log or a pipe with an empty line, which stood above
        # the error line of a clip found missing while the bars stood ready
        progress.console.quiet = not progress.console.is_interactive
        raise


@contextlib.contextmanager
def progress_bar(
    label: str, total: int | None, *, unit: str = "frames", quiet: bool = False
) -> Iterator[Callable[[int], None]]:
    """Yields ``advance(n)`` of one bar (:func:`stage_bars`)."""
    with stage_bars(quiet=quiet) as bar:
        yield bar(label, total, unit)


def with_bars(job: Callable[[ProgressFactory], T], *, quiet: bool = False) -> T:
    """``job(bar)``, where ``bar(label, total)`` opens a progress bar for a stage, below
    the last stage's (:func:`stage_bars`)."""
    with stage_bars(quiet=quiet) as bar:
        return job(bar)


@contextlib.contextmanager
def batch_progress(
    files: int, *, quiet: bool = False
) -> Iterator[tuple[Callable[[], None], Callable[[int], None]]]:
    """One bar over a batch: files done of ``files``, and the frames written with their
    rate. Yields ``(file_done(), frames_done(n))``."""
    if quiet:
        yield (lambda: None), (lambda n: None)
        return
    columns = (
        TextColumn("[bold]files"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[frames]} frames{task.fields[rate]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=Console(stderr=True), transient=False) as progress:
        task = progress.add_task("files", total=files, frames=0, rate="")
        start = time.perf_counter()
        count = [0]

        def file_done() -> None:
            progress.advance(task, 1)

        def frames_done(n: int) -> None:
            count[0] += n
            rate = count[0] / max(time.perf_counter() - start, 1e-6)
            progress.update(task, frames=count[0], rate=f" ({rate:.1f}/s)")

        with _cleared_on_failure(progress):  # the files done stay, listed above it
            yield file_done, frames_done
