"""Locating FFmpeg, and widening the pipes to it.

FFmpeg is the one on PATH, else the static binary shipped in the ``imageio-ffmpeg``
wheel, so a fresh machine needs no system package.
"""

from __future__ import annotations

import functools
import shutil


@functools.cache
def ffmpeg_exe() -> str:
    found = shutil.which("ffmpeg")
    if found:
        return found
    import imageio_ffmpeg

    return imageio_ffmpeg.get_ffmpeg_exe()


PIPE_BYTES = 1 << 20  # Linux's default ceiling for an unprivileged pipe


def widen_pipe(stream) -> None:
    """Grow a pipe to 1 MiB (from 64 KiB), so a raw frame crosses in a few large writes
    instead of dozens of small ones; silently left alone where the OS does not allow it."""
    try:
        import fcntl

        fcntl.fcntl(stream.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
    except (ImportError, OSError, ValueError):
        pass
