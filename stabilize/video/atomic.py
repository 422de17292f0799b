"""Writing outputs atomically: a temporary file beside the target, renamed at the end."""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, overwrite: bool = False) -> Iterator[Path]:
    """A temporary path beside ``path``, renamed onto it only if the block succeeds.

    An interrupted or failed run leaves nothing under the final name. The temporary
    name keeps the suffix, so tools that pick a format from it still work, and carries
    this process's id, so that a later run can tell a killed run's leftover (swept here)
    from a running one's (left alone).
    """
    final = Path(path)
    if final.exists() and not overwrite:
        raise FileExistsError(f"{final} exists (use --overwrite to replace it)")
    final.parent.mkdir(parents=True, exist_ok=True)
    sweep_stale(final.parent, f".{final.stem}.*.partial*")
    fd, tmp = tempfile.mkstemp(
        prefix=f".{final.stem}.{os.getpid()}.", suffix=f".partial{final.suffix}", dir=final.parent
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


_OWNER = re.compile(r"\.(\d+)\.[^.]+\.partial")  # the pid in .NAME.PID.RANDOM.partial.SUFFIX


def sweep_stale(folder: Path, pattern: str = ".*.partial*", *, recursive: bool = False) -> int:
    """Remove the temporary outputs in ``folder`` whose process is gone (killed before it
    could clean up); those of a running process are left alone. Returns how many."""
    found = folder.rglob(pattern) if recursive else folder.glob(pattern)
    swept = 0
    for leftover in found:
        owner = _OWNER.search(leftover.name)
        if owner is None or not _running(int(owner.group(1))):
            leftover.unlink(missing_ok=True)
            swept += 1
    return swept


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process: alive
        return True
    return True
