"""Helpers the tests share: single-frame forms of the vectorised library functions, and
small synthetic inputs. Not part of the package: the library works on whole clips."""

from __future__ import annotations

import subprocess
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy import sparse

from rotation import so3
from stabilize.path.optimal import high_passed_velocity
from stabilize.video import ffmpeg_exe
from stabilize.warp.coverage import Framing
from stabilize.warp.lens import Lens
from stabilize.warp.remap import remap_from
from stabilize.warp.sources import lens_source, rolling_source

# The bundled sample: a rendered street clip with its truth, gyro log and frame times.
SAMPLE = Path(__file__).resolve().parents[2] / "samples" / "street"


def held_upright(clip: Path, folder: Path, rotation: int = 90) -> Path:
    """``clip`` tagged to be shown turned ``rotation``° (counter-clockwise), as a phone
    held upright records: the same stream, copied."""
    rotated = folder / f"upright{rotation}.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-display_rotation", str(rotation), "-i", str(clip)]
    subprocess.run([*cmd, "-c", "copy", str(rotated)], check=True)
    return rotated


def woven(clip: Path, folder: Path) -> Path:
    """``clip``'s frames woven in pairs into the two fields of one frame (top field
    first), an interlaced H.264 stream at half the rate, as a camcorder's 50i stores a
    50 fps scene."""
    out = folder / "woven.mp4"
    weave = ["-vf", "tinterlace=mode=interleave_top,setfield=tff", "-flags", "+ildct+ilme"]
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(clip), *weave, "-x264opts", "tff=1"]
    subprocess.run([*cmd, "-c:v", "libx264", "-crf", "14", "-c:a", "copy", str(out)], check=True)
    return out


def squeezed(folder: Path) -> Path:
    """The 640×360 sample stored 480×360 with 4:3 pixels (as HDV stores 1920×1080 in
    1440×1080): shown the same."""
    out = folder / "squeezed.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(SAMPLE / "clip.mp4"), "-vf"]
    subprocess.run([*cmd, "scale=480:360,setsar=4/3", "-crf", "12", str(out)], check=True)
    return out


def damaged(clip: Path, folder: Path, within: tuple[float, float] = (0.3, 0.6)) -> Path:
    """``clip`` as MPEG-TS with a stretch of its video packets damaged (by default from
    30% to 60% of the file, a byte in seven flipped), as a failing card or a broken
    stream leaves one: a fifth of the frames its packets list do not decode."""
    out = folder / "damaged.ts"
    encode = ["-c:v", "libx264", "-g", "10", "-c:a", "aac"]
    subprocess.run([ffmpeg_exe(), "-v", "error", "-i", str(clip), *encode, str(out)], check=True)
    data = bytearray(out.read_bytes())
    packets = len(data) // 188
    for k in range(max(int(packets * within[0]), 2), int(packets * within[1])):  # PAT, PMT
        p = 188 * k
        if data[p + 1] & 0x1F == 0x01 and data[p + 2] == 0x00:  # the video's PID, 0x100
            data[p + 30 : p + 188 : 7] = bytes(b ^ 0xFF for b in data[p + 30 : p + 188 : 7])
    out.write_bytes(bytes(data))
    return out


def boxed(clip: Path, folder: Path, pad: str, before: str = "") -> Path:
    """``clip`` (through the FFmpeg filter ``before``, if any) framed by black bars baked
    into it, as FFmpeg's ``pad`` filter puts them (``W:H:X:Y``): a letterbox or a
    pillarbox."""
    out = folder / "boxed.mp4"
    chain = ",".join(f for f in (before, f"pad={pad}:black") if f)
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(clip), "-vf", chain]
    subprocess.run([*cmd, "-crf", "12", "-c:a", "copy", str(out)], check=True)
    return out


def combing(frame: NDArray) -> float:
    """How combed a frame's grey levels are: the mean of |row − the mean of its two
    neighbours| over that of |row above − row below|. Where the fields of a moving scene
    are woven, each row differs from both neighbours (a rendered 320×180 street shaken
    1.5°: about 1.3); a progressive frame's rows lie between theirs (about 0.5)."""
    y = frame.astype(np.float32)
    if y.ndim == 3:
        y = y.mean(axis=2)
    teeth = np.abs(y[1:-1] - (y[:-2] + y[2:]) / 2).mean()
    return float(teeth / (np.abs(y[:-2] - y[2:]).mean() + 1e-6))


def covers(K, C, zoom, size, rows=None, lens: Lens | None = None) -> bool:
    """Whether one frame's output at ``zoom`` lies inside its warped input."""
    return bool(Framing(K, size, rows, lens).covered(np.asarray(C)[None], np.array([zoom]))[0])


def required_zoom(K, C, size, max_zoom: float = 4.0, rows=None, lens=None) -> float:
    """One frame's least covering zoom."""
    return float(Framing(K, size, rows, lens).required_zooms(np.asarray(C)[None], max_zoom)[0])


def warp_frame_rolling(frame: NDArray, H: NDArray, rows: NDArray) -> NDArray:
    """Warp by row-dependent homographies H (B, 3, 3) at input knot rows (B,)."""
    return remap_from(frame, rolling_source(H, rows))


def warp_frame_lens(frame: NDArray, lens: Lens, C: NDArray, zoom: float, rows=None) -> NDArray:
    """Undistort → rotate → redistort in one remap."""
    return remap_from(frame, lens_source(lens, C, zoom, rows))


def from_rgb(rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """RGB (H, W, 3) → I420 (limited range, BT.601)."""
    return cv2.cvtColor(rgb, cv2.COLOR_RGB2YUV_I420)


def shaky_path(n=120, seed=0, shake_deg=1.0, pan_deg_s=0.0):
    """(times, O): a handheld orientation path at 30 fps, with an optional pan."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 30.0
    angles = np.radians(shake_deg) * rng.normal(size=(n, 3))
    angles[:, 1] += np.radians(pan_deg_s) * t
    O = so3.exp_so3(-angles)  # world → camera
    return t, O


def shake_operator(n: int, k: int, sigma: float) -> sparse.csr_array:
    """(I - G_σ) Δ ⊗ I_k: the high-passed velocity of a path of n frames and k
    components, flattened frame-major (:func:`high_passed_velocity` for each): the
    operator whose HᵀH the path programme's cost makes from its n × n core."""
    return sparse.kron(high_passed_velocity(n, sigma), sparse.eye_array(k)).tocsr()
