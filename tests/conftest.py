"""Shared fixtures: the location of ../shared, skipping cleanly where it is absent."""

from __future__ import annotations

from pathlib import Path

import pytest

# numba's settings (rotation.cache: the cache folder, plain messages) before any test
# module loads numba: flow.texture and stabilize.gyro.integrate load it without rotation,
# and a numba loaded first colours its messages through colorama, which rebinds
# sys.stderr from the thread that compiles (tests found capsys emptied)
import rotation  # noqa: F401

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared() -> Path:
    if not SHARED.is_dir():
        pytest.skip(f"../shared is not beside the checkout (looked in {SHARED})")
    return SHARED
