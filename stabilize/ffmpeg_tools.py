"""Locating FFmpeg, and writing outputs atomically.

FFmpeg is the one on PATH, else the static binary shipped in the ``imageio-ffmpeg``
wheel, so a fresh machine needs no system package.
"""

from __future__ import annotations

import contextlib
import functools
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path


@functools.cache
def ffmpeg_exe() -> str:
    found = shutil.which("ffmpeg")
    if found:
        return found
    import imageio_ffmpeg

    return imageio_ffmpeg.get_ffmpeg_exe()


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, overwrite: bool = False) -> Iterator[Path]:
    """A temporary path beside ``path``, renamed onto it only if the block succeeds.

    An interrupted or failed run leaves nothing under the final name. The temporary
    name keeps the suffix, so tools that pick a format from it still work.
    """
    final = Path(path)
    if final.exists() and not overwrite:
        raise FileExistsError(f"{final} exists (use --overwrite to replace it)")
    final.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{final.stem}.", suffix=f".partial{final.suffix}", dir=final.parent
    )
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp_path, 0o666 & ~umask)  # mkstemp makes it private; outputs are not
        os.replace(tmp_path, final)
    finally:
        tmp_path.unlink(missing_ok=True)


PIPE_BYTES = 1 << 20  # Linux's default ceiling for an unprivileged pipe


def widen_pipe(stream) -> None:
    """Grow a pipe to 1 MiB (from 64 KiB), so a raw frame crosses in a few large writes
    instead of dozens of small ones; silently left alone where the OS does not allow it."""
    try:
        import fcntl

        fcntl.fcntl(stream.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
    except (ImportError, OSError, ValueError):
        pass
