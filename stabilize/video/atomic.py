"""Writing outputs atomically: a temporary file beside the target, renamed at the end;
an image sequence's pictures in a temporary folder beside them, moved in at the end."""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from stabilize.video.containers import container_for
from stabilize.video.sequence import is_pattern, sequence_files


def check_absent(path: str | os.PathLike, overwrite: bool) -> None:
    """FileExistsError where ``path`` exists (an image sequence: any of its pictures)
    and may not be replaced; ValueError where it is a folder, which no output replaces
    (``out.mp4/`` made by mistake: the run failed once its work was done), or a pipe or
    a device, which the final rename would replace with a file."""
    final = Path(path)
    if final.is_dir():
        raise ValueError(
            f"{final} is a folder: name the output file, e.g. {final / 'out'}"
            f"{final.suffix or '.mp4'}"
        )
    if final.exists() and not final.is_file():
        # renamed over, even with --overwrite: a FIFO or a device node became a plain file
        raise ValueError(f"{final} is a pipe or a device, not a file: name a file")
    if overwrite:
        return
    if is_sequence(final) and (found := sequence_files(final)):
        raise FileExistsError(
            f"{final}: {len(found)} pictures of this sequence exist (use --overwrite to "
            "replace them)"
        )
    if final.exists():
        raise FileExistsError(f"{final} exists (use --overwrite to replace it)")


def check_not_input(output: str | os.PathLike, *inputs: str | os.PathLike) -> None:
    """ValueError where writing ``output`` would replace one of ``inputs``: the same file
    by any name (a link, another spelling), or a picture of an input image sequence.
    ``--overwrite`` never reaches an input: ``rotations clip.mp4 -o clip.mp4`` replaced
    the clip with its CSV, and ``evaluate --plot`` a picture of its input sequence."""
    out = Path(output)
    if not out.exists():
        return
    for source in inputs:
        files = sequence_files(source).values() if is_pattern(source) else [Path(source)]
        if any(f.exists() and os.path.samefile(f, out) for f in files):
            raise ValueError(f"{out} is the input {source}; choose another name")


def is_sequence(path: Path) -> bool:
    """Whether an output is an image sequence: a pattern in a picture format's suffix
    (``frames/%05d.png``; a video named ``50%done.mp4`` is one file)."""
    return is_pattern(path) and container_for(path).pictures is not None


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, overwrite: bool = False) -> Iterator[Path]:
    """A temporary path beside ``path``, renamed onto it only if the block succeeds.

    An interrupted or failed run leaves nothing under the final name. The temporary
    name keeps the suffix, so tools that pick a format from it still work, and carries
    this process's id, so that a later run can tell a killed run's leftover (swept here)
    from a running one's (left alone). An image sequence (``frames/%05d.png``) is
    written into a temporary folder beside it, whose pictures replace the old
    sequence's (every one of them, with ``overwrite``) once the block succeeds.
    """
    final = Path(path)
    check_absent(final, overwrite)
    final.parent.mkdir(parents=True, exist_ok=True)
    if is_sequence(final):
        with _atomic_sequence(final) as tmp:
            yield tmp
        return
    stem = short_stem(final.stem)
    sweep_stale(final.parent, f".{stem}.*.partial*")
    fd, tmp = tempfile.mkstemp(
        prefix=f".{stem}.{os.getpid()}.", suffix=f".partial{final.suffix}", dir=final.parent
    )
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        _publish(tmp_path, final)
    finally:
        tmp_path.unlink(missing_ok=True)


@contextlib.contextmanager
def atomic_folder(folder: str | os.PathLike) -> Iterator[Path]:
    """A temporary folder beside ``folder`` (made if missing), whose files are moved into
    it, each replacing its namesake, only if the block succeeds: a report's files all
    come from one run, and a failed run leaves the old ones as they were."""
    final = Path(folder).resolve()
    final.mkdir(parents=True, exist_ok=True)
    with _staging(final.parent, final.name) as tmp:
        yield tmp
        _move_in(tmp, final)


@contextlib.contextmanager
def _atomic_sequence(final: Path) -> Iterator[Path]:
    # FFmpeg reads a % anywhere in the path as the frame number's place
    with _staging(final.parent, final.stem.replace("%", "")) as tmp:
        yield tmp / final.name
        for old in sequence_files(final).values():
            old.unlink()
        _move_in(tmp, final.parent)


@contextlib.contextmanager
def _staging(parent: Path, stem: str) -> Iterator[Path]:
    """A hidden temporary folder in ``parent`` (``.STEM.PID.RANDOM.partial``, so that a
    killed run's is swept by the next), removed after the block."""
    stem = short_stem(stem)
    sweep_stale(parent, f".{stem}.*.partial")
    tmp = Path(tempfile.mkdtemp(prefix=f".{stem}.{os.getpid()}.", suffix=".partial", dir=parent))
    try:
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _move_in(tmp: Path, dest: Path) -> None:
    """Every file made in ``tmp`` moved into ``dest``, each replacing its namesake."""
    for made in sorted(tmp.iterdir()):
        _publish(made, dest / made.name)


def _publish(made: Path, final: Path) -> None:
    """``made`` renamed onto ``final``, with the permissions outputs get: mkstemp and
    mkdtemp make what they create private."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(made, 0o666 & ~umask)
    os.replace(made, final)


# Bytes a file's name may hold (ext4, APFS, NTFS: 255), and those a temporary name adds to
# its stem: ".", ".PID.", 8 random, ".partial" and a suffix of up to 16
NAME_MAX = 255
TEMP_NAME_BYTES = 48


def short_stem(stem: str) -> str:
    """``stem`` cut, on a character's boundary, to leave a temporary name beside it within
    :data:`NAME_MAX` bytes: a 249-character output's ``.NAME.PID.RANDOM.partial.mp4``
    failed with "File name too long" once the work was done.

    A byte that is not UTF-8 (a Latin-1 name off an old card: ``caf\\xe9``) is written
    as U+FFFD: the name's surrogate escapes failed it ("surrogates not allowed").

    >>> len(short_stem("é" * 200).encode()), short_stem("take-1"), short_stem("caf\\udce9")
    (206, 'take-1', 'caf�')
    """
    clean = stem.encode(errors="surrogateescape").decode(errors="replace")
    return clean.encode()[: NAME_MAX - TEMP_NAME_BYTES].decode(errors="ignore")


_OWNER = re.compile(r"\.(\d+)\.[^.]+\.partial")  # the pid in .NAME.PID.RANDOM.partial.SUFFIX


def sweep_stale(folder: Path, pattern: str = ".*.partial*", *, recursive: bool = False) -> int:
    """Remove the temporary outputs in ``folder`` whose process is gone (killed before it
    could clean up); those of a running process are left alone. Returns how many."""
    found = folder.rglob(pattern) if recursive else folder.glob(pattern)
    swept = 0
    for leftover in found:
        owner = _OWNER.search(leftover.name)
        if owner is None or not _running(int(owner.group(1))):
            if leftover.is_dir():  # an image sequence's
                shutil.rmtree(leftover, ignore_errors=True)
            else:
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
