"""The compiled kernels live in the user's cache folder, never beside the sources."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import rotation
from rotation.cache import cache_dir


def test_the_cache_is_the_users_folder_not_the_package(monkeypatch, tmp_path):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.delenv("HOUGH_STABILIZE_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    if sys.platform.startswith("linux"):
        assert cache_dir() == tmp_path / "hough-stabilize" / "numba"
    package = Path(rotation.__file__).parent
    assert package not in cache_dir().parents
    monkeypatch.setenv("HOUGH_STABILIZE_CACHE", str(tmp_path / "mine"))
    assert cache_dir() == tmp_path / "mine" / "numba"


def test_numba_is_pointed_there_before_any_kernel_is_defined(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["HOUGH_STABILIZE_CACHE"] = str(tmp_path)
    code = "import rotation; from numba.core import config; print(config.CACHE_DIR)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip() == str(tmp_path / "numba"), out.stderr


def test_numba_formats_its_messages_without_rebinding_the_standard_streams():
    # colorama's init()/deinit() around each message numba formats while compiling
    # rebound sys.stderr 32,601 times in one first compile, from the compiling thread.
    # Asked in a fresh interpreter: in this one, Ray may have put its own colorama on
    # sys.path, which a plain environment lacks (and without it numba uses none)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING"}
    code = (
        "import rotation\n"
        "try:\n"
        "    import colorama\n"
        "except ImportError:\n"
        "    raise SystemExit('no colorama')\n"
        "calls = []\n"
        "colorama.init = colorama.deinit = lambda *a, **k: calls.append(1)\n"
        "from numba.core import errors\n"
        "errors.termcolor().highlight('a message')\n"
        "print(len(calls))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if out.stderr.strip() == "no colorama":
        pytest.skip("colorama is not installed: numba colours nothing")
    assert out.stdout.strip() == "0", out.stderr


def test_the_kernels_count_as_cached_only_where_this_install_compiled_them(monkeypatch, tmp_path):
    # a second checkout compiled for 16 s without the notice: another install's index
    # anywhere in the cache counted
    import numba.core.caching

    from rotation.cache import KERNEL_INDEX, cache_subfolder, kernels_cached

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    sources = Path(os.path.abspath(rotation.__file__)).parent
    index = KERNEL_INDEX.replace("*", "337.py311")
    # numba's own name for the folder it keeps these sources' kernels in
    named = numba.core.caching._CacheLocator.get_suitable_cache_subpath(str(sources / "hough.py"))
    assert cache_subfolder(sources) == named
    other = tmp_path / cache_subfolder(tmp_path / "another-checkout" / "rotation")
    other.mkdir()
    (other / index).write_bytes(b"")
    assert not kernels_cached()
    own = tmp_path / named
    own.mkdir()
    (own / index).write_bytes(b"")
    assert kernels_cached()
    stale = (sources / "hough.py").stat().st_mtime - 60  # compiled before the source changed
    os.utime(own / index, (stale, stale))
    assert not kernels_cached()
