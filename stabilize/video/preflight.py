"""Checks made before any decoding: can the output be written, and will the encoder take
the options? A mistake found here costs a fraction of a second, not a whole pass.
"""

from __future__ import annotations

import errno
import functools
import os
import re
import subprocess
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from stabilize.video.binary import ffmpeg_exe
from stabilize.video.containers import container_for
from stabilize.video.encode import EncodeError, Encoding, FrameWriter, Mux, output_args
from stabilize.video.encoders import VIDEO_ONLY
from stabilize.video.retime import is_variable_rate
from stabilize.video.sequence import is_pattern


class OutputError(ValueError):
    """An output that cannot be written where it was asked for; one line."""


def check_writable(path: str | Path) -> None:
    """That a file can be created beside ``path`` (its folder made if missing): by making
    one there, the only test that answers for read-only disks, permissions and /proc."""
    folder = Path(path).parent
    existing = next((p for p in (folder, *folder.parents) if p.exists()), Path("/"))
    if not existing.is_dir():
        raise OutputError(f"{Path(path)}: {existing} is a file, not a folder")
    target = folder if folder.exists() else existing
    try:
        fd, probe = tempfile.mkstemp(prefix=".stabilize-check.", dir=target)
    except OSError as err:
        raise OutputError(f"cannot write in {target}: {describe(err)}") from None
    os.close(fd)
    os.unlink(probe)


def check_encoder(
    path: str | Path, encoding: Encoding, size: tuple[int, int], fps: float = 30.0
) -> None:
    """That FFmpeg encodes two frames of (H, W) ``size`` at ``fps`` with these options
    into the container ``path``'s suffix names; else FFmpeg's own first complaint, in
    one line. (MXF takes broadcast rates alone: a 15 fps clip failed after pass 1.)"""
    h, w = size
    container = container_for(path)
    if container.pictures and not is_pattern(path):
        raise OutputError(
            f"{Path(path)} names one picture: name an image sequence with the frame's "
            f"number in it, e.g. {Path(path).with_name(Path(path).stem + '-%05d')}"
            f"{Path(path).suffix}"
        )
    if container.pictures and encoding.codec in VIDEO_ONLY:
        raise OutputError(
            f"--codec {encoding.codec} writes video, not pictures: leave it out for "
            f"{Path(path).suffix} pictures"
        )
    with tempfile.TemporaryDirectory(prefix="stabilize-check.") as tmp:
        out = Path(tmp) / f"check{'%d' if container.pictures else ''}{Path(path).suffix}"
        cmd = [ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-nostdin", "-y"]
        cmd += ["-f", "lavfi", "-i", f"color=black:s={w}x{h}:r={fps!r}", "-frames:v", "2"]
        cmd += [*output_args(out, encoding, container), str(out)]
        result = subprocess.run(cmd, capture_output=True, text=True, errors="replace")
    if result.returncode != 0:
        raise OutputError(
            _cannot_write(Path(path), encoding, result.stderr, result.returncode, fps)
        )


def check_pix_fmt(encoding: Encoding) -> None:
    """That the encoder writes the pixel format asked for (``--pix-fmt``), as FFmpeg lists
    its formats: given another, FFmpeg picks one it writes and says so only in a warning
    (libx264 asked for yuv410p wrote yuv420p). ``encoding`` is made whole
    (:meth:`Encoding.for_frames`): its codec named."""
    codec, pix_fmt = encoding.codec, encoding.pix_fmt
    if codec is None or pix_fmt is None:
        return
    written = encoder_pix_fmts(codec)
    if not written or pix_fmt in written:
        return
    raise OutputError(
        f"--pix-fmt {pix_fmt}: {codec} does not write it; it writes {', '.join(written)}"
    )


@functools.lru_cache(maxsize=32)
def encoder_pix_fmts(codec: str) -> tuple[str, ...]:
    """The pixel formats FFmpeg lists for an encoder (none where it lists none)."""
    cmd = [ffmpeg_exe(), "-hide_banner", "-h", f"encoder={codec}"]
    said = subprocess.run(cmd, capture_output=True, text=True, errors="replace").stdout
    listed = re.search(r"Supported pixel formats:(.*)", said)
    return tuple(listed.group(1).split()) if listed else ()


# FFmpeg's words where the suffix names no muxer, and where its muxer holds no video
NO_MUXER, NO_VIDEO = "Unable to choose an output format", "does not contain any stream"
NO_RATE = "Unsupported frame rate"  # and where its muxer holds broadcast frame rates alone
SOME_CONTAINERS = ".mp4, .mov, .mkv, .webm"


def _cannot_write(path: Path, encoding: Encoding, stderr: str, code: int, fps: float) -> str:
    """Why FFmpeg cannot write ``path`` with ``encoding``: the suffix named in the
    user's words where it names no video container (the check's own file was named,
    ``/tmp/stabilize-check.y29r5892/check.xyz``), else FFmpeg's first complaint."""
    if NO_MUXER in stderr and not path.suffix:
        return f"{path}: no suffix names its container: give {SOME_CONTAINERS}, … ({path}.mp4)"
    if NO_MUXER in stderr:
        return f"{path}: {path.suffix} names no container FFmpeg writes: give {SOME_CONTAINERS}, …"
    if NO_VIDEO in stderr:
        return f"{path}: {path.suffix} holds no video (audio only): give {SOME_CONTAINERS}, …"
    if NO_RATE in stderr:
        return (
            f"{path}: {path.suffix} holds broadcast frame rates alone (23.976, 24, 25, 29.97, "
            f"30, 50, 59.94, 60, …), not this clip's {fps:.5g} fps: give .mov, .mkv, …"
        )
    first = (stderr.strip().splitlines() or [f"exit status {code}"])[0]
    codec = encoding.codec_for(container_for(path))
    return f"FFmpeg cannot write {codec} (preset {encoding.preset}) as {path.suffix}: {first}"


def check_streams(
    path: str | Path, encoding: Encoding, size: tuple[int, int], mux: Mux, fps: float = 30.0
) -> None:
    """That FFmpeg writes the source's tracks, as ``mux`` keeps them, beside two frames of
    (H, W) ``size`` at ``fps`` into the container ``path``'s suffix names (a tenth of a
    second of them): a track the container cannot hold failed only once the work was
    done (AAC audio in MXF, before :data:`~stabilize.video.containers.MXF` was registered)."""
    if not mux.inputs or not container_for(path).timed:  # pictures take no tracks
        return
    brief = replace(mux, args=(*mux.args, "-t", "0.1"))
    with tempfile.TemporaryDirectory(prefix="stabilize-check.") as tmp:
        out = Path(tmp) / f"check{Path(path).suffix}"
        try:
            with FrameWriter(out, size, fps, encoding, brief) as writer:
                for _ in range(2):
                    writer.write(np.zeros(writer.shape, writer.dtype))
        except EncodeError as err:
            reason = str(err).removeprefix("the encoder failed: ")
            raise OutputError(
                f"{Path(path)}: the source's tracks cannot go into {Path(path).suffix} as "
                f"they are (FFmpeg: {reason}); another container, e.g. .mkv, takes them"
            ) from None


def check_times(path: str | Path, times: NDArray) -> None:
    """That the container ``path``'s suffix names keeps the frames' ``times`` (s): MXF
    holds one constant rate, where a phone's clip varies its own (remuxed at each
    frame's time, :func:`stabilize.video.retime.retime`, into any other)."""
    container = container_for(path)
    if container.variable_rate or not is_variable_rate(times):
        return
    mean = (len(times) - 1) / (times[-1] - times[0])
    raise OutputError(
        f"{Path(path)}: {container.name or container.muxer} holds one constant frame rate, "
        f"and this clip's varies ({mean:.2f} fps on average): give .mov, .mp4 or .mkv, "
        "which keep each frame's time"
    )


def describe(err: OSError) -> str:
    """An OS error's reason in words, the disk's fullness named."""
    if err.errno == errno.ENOSPC:
        return "the disk is full"
    return err.strerror or str(err)
