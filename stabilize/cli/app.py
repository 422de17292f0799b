"""The typer app that every command registers with, its version flag, and the one way
a command fails: one ``error:`` line on stderr and exit status 2."""

from __future__ import annotations

from collections.abc import Callable
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import NoReturn, TypeVar

import typer

T = TypeVar("T")

app = typer.Typer(
    name="stabilize",
    help=(
        "**stabilize IN OUT** turns a shaky clip into a steady one (the main job: "
        "`stabilize run --help` lists its options).\n\n"
        "Video stabilisation from a robust camera-rotation estimator "
        "(Hough transform on SO(3), ICCV 2023). The other commands estimate rotations "
        "only, render test clips, score results, compare with a gyro log, or stabilise "
        "a folder."
    ),
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="markdown",
)


def _no_placeholder_on_flags() -> None:
    """typer 0.29 shows every flag with a '<bool>' placeholder in the help, as if it took
    a value; a flag takes none, so it gets no placeholder."""
    from typer.core import TyperOption

    shown = TyperOption.display_type_rich

    def display_type_rich(self, ctx):
        return None if self.is_flag else shown(self, ctx)

    TyperOption.display_type_rich = display_type_rich


_no_placeholder_on_flags()


def package_version() -> str:
    """The installed package's version ('unknown' in a source tree never installed)."""
    try:
        return version("hough-stabilize")
    except PackageNotFoundError:
        return "unknown"


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"stabilize {package_version()}")
        raise typer.Exit()


@app.callback()
def _root(
    version_flag: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Video stabilisation from a robust camera-rotation estimator."""


BAD_INPUT = 2  # exit status: a bad input or option (nothing was done)
FAILED = 1  # exit status: a failure while working


LONGEST = 400  # characters of a message shown on its error line


def one_line(message: str) -> str:
    """A message as one line: its whitespace and line breaks collapsed, cut at
    ``LONGEST`` characters (a library's message may carry a whole array)."""
    line = " ".join(str(message).split())
    return line if len(line) <= LONGEST else line[: LONGEST - 1] + "…"


def fail(message: str, status: int = BAD_INPUT) -> NoReturn:
    """One clear line on stderr and a non-zero exit: 2 for a bad input or option, 1 for a
    failure while working."""
    typer.echo(f"error: {one_line(message)}", err=True)
    raise typer.Exit(status)


def run_or_fail(work: Callable[[], T]) -> T:
    """``work()``, its failure turned into one ``error:`` line: status 2 for a bad input
    or option (ValueError and its kin, raised before any work), 1 for a failure while
    working (the encoder, the disk)."""
    from stabilize.video.preflight import describe

    try:
        return work()
    except typer.Exit:
        raise
    except (ValueError, FileExistsError, FileNotFoundError) as err:
        fail(str(err))
    except OSError as err:
        where = f"{err.filename}: " if getattr(err, "filename", None) else ""
        fail(f"{where}{describe(err)}", FAILED)
    except RuntimeError as err:
        fail(str(err).splitlines()[0] if str(err) else type(err).__name__, FAILED)


def notice(message: str) -> None:
    """A line on stderr about something the job changed or left out (never silently)."""
    typer.echo(f"notice: {message}", err=True)


def check_report_folder(folder: Path) -> None:
    """A ``--report`` target must be a folder, or not yet exist."""
    if folder.exists() and not folder.is_dir():
        fail(f"--report {folder}: is a file; give a folder (it is made if missing)")


def announce_compiling() -> None:
    """A one-line notice when the estimator's kernels are not compiled yet: the first
    run spends about 15 s compiling them (cached for every later run)."""
    from stabilize.pipeline import compiling_notice

    for line in compiling_notice():
        notice(line)
