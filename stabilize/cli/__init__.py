"""The ``stabilize`` command line: one typer app, one module per command.

``stabilize IN OUT [options]`` is the main job (:mod:`.run`); ``rotations``, ``synth``,
``evaluate``, ``compare`` and ``batch`` are subcommands. The options several commands
share are declared once (:mod:`.options`), with their defaults taken from
:class:`stabilize.settings.Settings`. Commands import the pipeline only when they run,
so ``--help`` stays fast.
"""

from __future__ import annotations

import os
import signal
import sys

import typer
from typer.exceptions import TyperException

from stabilize.cli import batch, compare, evaluate, rotations, run, synth
from stabilize.cli.app import BAD_INPUT, FAILED, app, one_line

COMMANDS = ("run", "rotations", "synth", "evaluate", "compare", "batch")
__all__ = ["COMMANDS", "app", "batch", "compare", "evaluate", "main", "rotations", "run", "synth"]


TOP_LEVEL = ("--help", "-h", "--version")  # what the app itself answers
DEBUG = "STABILIZE_DEBUG"  # set: an internal error ends with its traceback
INTERRUPTED = 130  # exit status after Ctrl-C (128 + SIGINT, as shells report it)
TERMINATED = 143  # after SIGTERM (128 + 15): `kill`'s, `timeout`'s, a job scheduler's


def _stop_on_sigterm() -> tuple[list[int], object]:
    """SIGTERM ends a job as Ctrl-C does, its temporary files removed and one line said:
    it ended the process where it stood, leaving a hidden ``.out.PID.….partial.mp4``
    (700 kB, 2 s into pass 2) and no word. Returns the list the signal is noted in, and
    the handler it replaced (None off the main thread, where none can be set)."""
    heard: list[int] = []

    def stop(signum: int, _frame) -> None:
        heard.append(signum)
        raise KeyboardInterrupt

    try:
        return heard, signal.signal(signal.SIGTERM, stop)
    except ValueError:  # not the main thread: Python sets handlers there alone
        return heard, None


def main() -> None:
    """Console-script entry point.

    A line that names no command runs the main job, wherever its options stand
    (``stabilize -q in.mp4 out.mp4``). A usage mistake is one ``error:`` line and exit
    status 2, as every other failure; Ctrl-C ends with one line and status 130, SIGTERM
    with one line and 143; a fault of ours (an exception no command turned into an
    ``error:`` line) one line and status 1.
    """
    args = sys.argv[1:]
    if args and args[0] not in COMMANDS and args[0] not in TOP_LEVEL:
        args = ["run", *args]
    terminated, previous = _stop_on_sigterm()  # a batch's workers too (batch._stop)
    try:
        status = app(args=args, prog_name="stabilize", standalone_mode=False)
    except TyperException as err:  # click's usage errors, in typer's own copy of click
        message = err.format_message() if hasattr(err, "format_message") else str(err)
        if message:  # (no arguments at all: the help was shown, and that is all)
            typer.echo(f"error: {message}", err=True)
        status = getattr(err, "exit_code", BAD_INPUT)
    except KeyboardInterrupt:  # outside a command (typer answers those itself, below)
        status = INTERRUPTED
    except Exception as err:  # a fault of ours, not of the input: one line, not a traceback
        if os.environ.get(DEBUG):
            raise
        typer.echo(
            f"error: internal error ({type(err).__name__}: {one_line(str(err))}); nothing was "
            f"written under the output's name; set {DEBUG}=1 for the traceback, and please "
            "report it",
            err=True,
        )
        status = FAILED
    if status == INTERRUPTED:  # typer turns Ctrl-C within a command into this, silently
        status = TERMINATED if terminated else INTERRUPTED
        how = "terminated (SIGTERM)" if terminated else "interrupted"
        typer.echo(f"error: {how}; no output was left half-written under its name", err=True)
    if previous is not None:
        signal.signal(signal.SIGTERM, previous)
    sys.exit(status or 0)


if __name__ == "__main__":
    main()
