"""Where numba keeps the compiled kernels: the user's cache folder, never site-packages.

A cache beside the sources breaks an installed package: pip leaves the folder behind
when it replaces the package, and Python then reads it as an empty namespace package.
So the kernels are cached, by platform convention, in

* Linux and others: ``$XDG_CACHE_HOME/hough-stabilize/numba`` (``~/.cache/...``);
* macOS: ``~/Library/Caches/hough-stabilize/numba``;
* Windows: ``%LOCALAPPDATA%\\hough-stabilize\\numba``;

or wherever ``$HOUGH_STABILIZE_CACHE`` says; numba's own ``$NUMBA_CACHE_DIR``, if set,
wins. This module is imported before any kernel is defined, and without importing numba
(about 0.2 s): where numba is not loaded yet, the folder goes into ``NUMBA_CACHE_DIR``,
which numba reads when it loads.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

KERNEL_INDEX = "hough.estimate_chunk-*.nbi"  # the estimator's main kernel, once compiled


def cache_dir() -> Path:
    """The folder numba caches the kernels in."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    if os.environ.get("HOUGH_STABILIZE_CACHE"):
        return Path(os.environ["HOUGH_STABILIZE_CACHE"]) / "numba"
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local"))
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "hough-stabilize" / "numba"


def use_cache_dir() -> None:
    """Point numba's cache at :func:`cache_dir` (before the kernels are decorated)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    if "numba" in sys.modules:  # loaded already: its configuration is read
        from numba.core import config

        config.CACHE_DIR = str(cache_dir())
    else:  # read when numba loads
        os.environ["NUMBA_CACHE_DIR"] = str(cache_dir())


def kernels_cached() -> bool:
    """Whether the estimator's kernels have been compiled and cached before (else the
    first estimate compiles them, which takes a while)."""
    folder = cache_dir()
    return folder.is_dir() and any(folder.rglob(KERNEL_INDEX))
