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
    starts (``warm_up``), with every later run's thread queued behind it; meanwhile, in
    a fresh clone under pytest-xdist, tests that read ``capsys`` found their ``error:``
    line gone to pytest's own capture instead (5–10 of the battery's 80, reproduced 4 of
    4 with an empty cache; none with the kernels loaded first)."""
    from rotation.hough import warm_up

    warm_up()
