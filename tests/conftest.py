"""Shared fixtures: the location of ../shared, skipping cleanly where it is absent."""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared() -> Path:
    if not SHARED.is_dir():
        pytest.skip(f"../shared is not beside the checkout (looked in {SHARED})")
    return SHARED


@pytest.fixture(scope="session", autouse=True)
def compiled_kernels() -> None:
    """The estimator's kernels loaded (compiled, on a fresh cache) before the first test.

    Left to the first runs, the compile took about 20 s on the daemon threads each run
    starts (``warm_up``), every later run's thread queued behind it, and meanwhile tests
    reading ``capsys`` found their ``error:`` line in pytest's own capture instead: with
    an empty cache, 5–10 of the battery's 80 failed under ``-n 2`` (4 of 4 tries) and 1
    in one process; none with the kernels loaded first. Which call moved ``sys.stderr``
    was not found; no test now runs beside a compile."""
    from rotation.hough import warm_up

    warm_up()
