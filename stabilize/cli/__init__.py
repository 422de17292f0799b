"""The ``stabilize`` command line: one typer app, one module per command.

``stabilize IN OUT [options]`` is the main job (:mod:`.run`); ``rotations``, ``synth``,
``evaluate``, ``compare`` and ``batch`` are subcommands. The options several commands
share are declared once (:mod:`.options`), with their defaults taken from
:class:`stabilize.settings.Settings`. Commands import the pipeline only when they run,
so ``--help`` stays fast.
"""

from __future__ import annotations

import sys

from stabilize.cli import batch, compare, evaluate, rotations, run, synth
from stabilize.cli.app import app

COMMANDS = ("run", "rotations", "synth", "evaluate", "compare", "batch")
__all__ = ["COMMANDS", "app", "batch", "compare", "evaluate", "main", "rotations", "run", "synth"]


def main() -> None:
    """Console-script entry point: a first argument that is no command runs the main job."""
    args = sys.argv[1:]
    if args and not args[0].startswith("-") and args[0] not in COMMANDS:
        args = ["run", *args]
    app(args=args, prog_name="stabilize")


if __name__ == "__main__":
    main()
