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


@contextlib.contextmanager
def progress_bar(
    label: str, total: int | None, *, unit: str = "frames", quiet: bool = False
) -> Iterator[Callable[[int], None]]:
    """Yields ``advance(n)``; shows rate (units/s) and ETA on stderr."""
    if quiet:
        yield lambda n=1: None
        return
    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[rate]}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=Console(stderr=True), transient=False) as progress:
        task = progress.add_task(label, total=total, rate="")

        def advance(n: int = 1) -> None:
            progress.advance(task, n)
            speed = progress.tasks[0].speed
            if speed:
                progress.update(task, rate=f"{speed:.1f} {unit}/s")

        try:
            yield advance
        except BaseException:
            progress.live.transient = True  # a failure leaves no half bar above its message
            raise


def with_bars(job: Callable[[ProgressFactory], T], *, quiet: bool = False) -> T:
    """``job(bar)``, where ``bar(label, total)`` opens a progress bar for a stage; the
    bars stay until the job is done, and are cleared when it fails."""
    with contextlib.ExitStack() as stack:

        def bar(label: str, total: int | None) -> Callable[[int], None]:
            return stack.enter_context(progress_bar(label, total, quiet=quiet))

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

        yield file_done, frames_done
