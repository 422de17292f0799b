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
which numba reads when it loads. So is :func:`use_plain_messages`' setting.
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


def use_plain_messages() -> None:
    """Keep numba from colouring its messages (before it loads; once loaded, it stays).

    With colorama installed, numba formats each message it raises and catches while
    compiling inside colorama's ``init()``/``deinit()``, which rebind ``sys.stdout`` and
    ``sys.stderr`` from whichever thread compiles: sys.stderr 32,601 times in one first
    compile of the kernels. They compile on a thread while the job goes on
    (``warm_up``), so a ``deinit()`` there put back a stream the main thread had
    replaced since, and a host that redirects them lost what was written meanwhile:
    with an empty cache, 5–17 of 136 tests found their ``error:`` line gone from
    pytest's ``capsys`` (4 of 4 tries); none with this.
    """
    os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")


def kernels_cached() -> bool:
    """Whether this install's estimator kernels are cached, compiled from its sources as
    they are (else the first estimate compiles them, which takes a while).

    numba keeps a source folder's kernels in a subfolder of the cache of its own, named
    after the folder and the SHA-1 of its path (``_CacheLocator.get_suitable_cache_subpath``),
    and compiles again where the source is newer than what it cached. Any index anywhere
    in the cache used to count: a second checkout or virtual environment on a machine
    that had run another compiled for 16 s without the notice."""
    source = Path(os.path.abspath(__file__)).with_name("hough.py")
    folder = cache_dir() / cache_subfolder(source.parent)
    built = source.stat().st_mtime
    return folder.is_dir() and any(i.stat().st_mtime >= built for i in folder.glob(KERNEL_INDEX))


def cache_subfolder(sources: Path) -> str:
    """The subfolder of the cache numba keeps the kernels of the folder ``sources`` in:
    its name and the SHA-1 of its absolute path, as numba names it.

    >>> cache_subfolder(Path("/opt/rotation"))
    'rotation_8ca058647ea3af216d14fed72e80dc62099aa363'
    """
    import hashlib

    path = os.path.abspath(sources)
    return f"{os.path.basename(path)}_{hashlib.sha1(path.encode()).hexdigest()}"
