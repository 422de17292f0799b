"""Locating FFmpeg, widening the pipes to it, and reading what it says as it works.

FFmpeg is the one on PATH, else the static binary shipped in the ``imageio-ffmpeg``
wheel, so a fresh machine needs no system package.
"""

from __future__ import annotations

import contextlib
import functools
import os
import shutil
import signal
import subprocess
import threading
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from stabilize.video.sequence import image2_path

# The signals that end a run (Ctrl-C, and `kill`'s SIGTERM, which the CLI turns into an
# interrupt too)
INTERRUPTS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def interrupts_held() -> Iterator[None]:
    """Ctrl-C and SIGTERM held back until the block ends, then delivered as they came
    (each once), to the handlers that were there; off the main thread, where Python
    sets no handler, the block runs as it is.

    An interrupt inside :class:`subprocess.Popen` (while it waits to hear that the
    child's exec worked) raises with the child already started and no handle to it:
    an encoder left so wrote its file once the caller had removed it (a SIGTERM test
    found a ``.partial.mp4`` left, once in five fresh-clone runs of the suite)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    heard: list[int] = []
    before = {s: signal.signal(s, lambda signum, _frame: heard.append(signum)) for s in INTERRUPTS}
    try:
        yield
    finally:
        for s, handler in before.items():  # (None: a handler set outside Python)
            signal.signal(s, signal.SIG_DFL if handler is None else handler)
        for s in dict.fromkeys(heard):
            signal.raise_signal(s)


@functools.cache
def ffmpeg_exe() -> str:
    found = shutil.which("ffmpeg")
    if found:
        return found
    import imageio_ffmpeg

    return imageio_ffmpeg.get_ffmpeg_exe()


def local(path: str | Path, image2: bool = False) -> str:
    """``path`` as FFmpeg reads a local file whatever its name: absolute, so that a
    colon in a relative name (``take:2.mp4``, an ISO time ``10:11:12.mp4``) is not
    taken for a protocol's, which made such a clip "not a video FFmpeg can read". An
    image sequence's pattern (``image2``) has its other ``%`` escaped
    (:func:`~stabilize.video.sequence.image2_path`).

    >>> local("/clips/take:2.mp4"), local("/clips/50%/%d.png", image2=True)
    ('/clips/take:2.mp4', '/clips/50%%/%d.png')
    """
    full = os.path.abspath(path)
    return image2_path(full) if image2 else full


PIPE_BYTES = 1 << 20  # Linux's default ceiling for an unprivileged pipe
KEPT_LINES = 50  # of a child's messages, the first and the last this many


def widen_pipe(stream) -> None:
    """Grow a pipe to 1 MiB (from 64 KiB), so a raw frame crosses in a few large writes
    instead of dozens of small ones; silently left alone where the OS does not allow it."""
    try:
        import fcntl

        fcntl.fcntl(stream.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), PIPE_BYTES)
    except (ImportError, OSError, ValueError):
        pass


def filter_log(
    path: str | Path, chain: str, before: Sequence[str] = (), after: Sequence[str] = ()
) -> str:
    """What FFmpeg's video filters ``chain`` log (its stderr) over the first video
    stream of ``path``, decoded and thrown away: ``before`` are input options (which
    frames to decode), ``after`` output ones (how many to pass)."""
    cmd = [ffmpeg_exe(), "-hide_banner", "-nostdin", *before, "-i", local(path, "image2" in before)]
    cmd += ["-map", "0:v:0", "-vf", chain, *after, "-f", "null", "-"]
    return subprocess.run(cmd, capture_output=True, text=True, errors="replace").stderr


def drain(stream, keep: int = KEPT_LINES) -> Callable[[], str]:
    """Read a child's stderr as it comes, on a thread of its own; the function returned
    waits for its end and gives its first and last ``keep`` lines.

    A child writing more than the pipe holds while we read only its frames blocks for
    ever: a damaged 60 s clip's decoding errors (200 kB) stopped FFmpeg, and the job
    with it, where this reads them away as they come.
    """
    head: list[bytes] = []
    tail: deque[bytes] = deque(maxlen=keep)

    def read() -> None:
        with stream:
            for line in stream:
                (head if len(head) < keep else tail).append(line)

    thread = threading.Thread(target=read, daemon=True)
    thread.start()

    def said() -> str:
        thread.join()
        return b"".join([*head, *tail]).decode(errors="replace").strip()

    return said
