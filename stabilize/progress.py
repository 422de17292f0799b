"""How a long stage reports its work: a callback ``advance(n)`` per n items done.

The stages take one (default: :func:`no_progress`); the command line hands them rich
progress bars (:mod:`stabilize.cli.bars`), batch workers a queue.
"""

from __future__ import annotations

from collections.abc import Callable

Progress = Callable[[int], None]
# A stage's bar: (label, total or None) → its advance callback.
ProgressFactory = Callable[[str, "int | None"], Progress]


def no_progress(_: int = 1) -> None:
    """The callback that reports nowhere."""
    return None
