"""Rendered handheld clips whose every rotation is known, with a matching gyro log.

``render_clip(out_dir, SynthOptions(...))`` writes:

* ``clip.mp4``: H.264 with a short audio track;
* ``truth.csv``: per frame ``frame,t,rx,ry,rz,qw,qx,qy,qz,f,cx,cy``: the time (s), the
  rotation vector of R_t (this frame to the next; empty on the last frame), the
  orientation O_t as a quaternion, and K;
* ``gyro.csv``: OpenCamera Sensors layout ``x,y,z,t_ns`` (rad/s, no header), in the
  device's axes, with a known IMU-to-camera rotation, bias, noise and clock offset;
* ``timestamps.csv``: the frame times on the gyro clock (ns), as that app writes them;
* ``truth.json``: every parameter, K, R_cam_imu, bias, noise and the offset.

The output depends only on the options (the seed included).
"""

from __future__ import annotations

import csv
import json
import math
import multiprocessing as mp
import os
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field
from itertools import islice
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from rotation import so3
from rotation.camera import focal_from_fov, intrinsics
from rotation.synthetic import Street
from stabilize.synth import trajectory
from stabilize.synth.scene import Scene, cast, ground_truth_flow, random_crowd
from stabilize.synth.textures import load_background
from stabilize.synth.trajectory import Handheld
from stabilize.video import atomic_output
from stabilize.video.encode import Encoding, FrameWriter, sine_audio

# A phone's gyro axes against its camera's: x_cam = y_imu, y_cam = x_imu, z_cam = -z_imu.
SCENE_LENGTH_M = 150.0  # the street is drawn this far; beyond it, the background
DEFAULT_R_CAM_IMU = ((0.0, 1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, -1.0))


@dataclass(frozen=True)
class SynthOptions:
    seed: int = 0
    seconds: float = 4.0
    fps: float = 30.0
    size: tuple[int, int] = (540, 960)  # (H, W)
    hfov: float = 70.0
    crowd: int = 12
    walls: bool = True
    shake_deg: float = 1.0
    pan_deg: float = 10.0
    walk: float = 1.0
    bob_m: float = 0.02  # a walker's vertical bob and lateral sway (amplitudes, m): only
    sway_m: float = 0.015  # while walking; 0 and 0 make a dolly's steady translation
    rolling_shutter_ms: float = 0.0
    gyro_offset: float = 0.35  # gyro clock minus video clock, seconds
    gyro_rate: float = 400.0
    gyro_noise: float = 0.002  # rad/s, white, per axis
    gyro_bias: tuple[float, float, float] = (0.003, -0.002, 0.001)  # rad/s
    r_cam_imu: tuple = field(default=DEFAULT_R_CAM_IMU)
    background: str | None = None  # a cube-map image; None: procedural skyline
    crf: int = 18

    @property
    def n_frames(self) -> int:
        return max(2, int(round(self.seconds * self.fps)))

    @property
    def focal(self) -> float:
        return focal_from_fov(self.hfov, self.size[1])

    @property
    def motion(self) -> Handheld:
        """The camera path. Bob and sway come from walking: with walk=0 the camera only
        turns, which makes every pixel's flow a pure rotation."""
        walking = self.walk > 0
        return Handheld(
            self.seconds,
            self.seed,
            self.shake_deg,
            self.pan_deg,
            self.walk,
            bob_m=self.bob_m * walking,
            sway_m=self.sway_m * walking,
        )

    def K(self) -> NDArray[np.float64]:
        return intrinsics(self.focal, self.size)


def clip_times(opts: SynthOptions) -> NDArray[np.float64]:
    return np.arange(opts.n_frames) / opts.fps


def build_scene(opts: SynthOptions) -> Scene:
    rng = np.random.default_rng(opts.seed + 1)
    street = Street(length=SCENE_LENGTH_M, walls=opts.walls)
    reach = 30.0 + opts.walk * opts.seconds
    crowd = random_crowd(rng, opts.crowd, street, reach)
    bg = load_background(Path(opts.background) if opts.background else None, rng, sky_width(opts))
    return Scene.build(rng, street, crowd, bg)


def sky_width(opts: SynthOptions) -> int:
    """The procedural panorama's width: about as many pixels a degree as the clip's
    frame has, the nearest power of two from 1024 to 4096. A 960-wide clip up to 110° (and the
    sample's 640 at 70°) keeps 4096; a 320x180 test clip's 2048 takes 0.74 s to make,
    where 4096 took 2.81 s, most of a short clip's rendering."""
    across = 360.0 / opts.hfov * opts.size[1]
    return int(min(max(2 ** round(math.log2(across)), 1024), 4096))


def render_frame(
    opts: SynthOptions, scene: Scene, k: int, *, with_flow: bool = False
) -> tuple[NDArray[np.uint8], NDArray[np.float32] | None]:
    """Frame k, with the exact flow to frame k+1 if asked (None for the last frame).

    Under a rolling shutter row r is exposed at t + r / H · readout; ground-truth flow
    is only defined for a global shutter.
    """
    h, w = opts.size
    K = opts.K()
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    rays = np.stack([(xx - K[0, 2]) / K[0, 0], (yy - K[1, 2]) / K[1, 1], np.ones_like(xx)], -1)
    readout = opts.rolling_shutter_ms / 1000.0
    t = k / opts.fps
    t_rows = t + readout * np.arange(h) / h if readout else np.full(h, t)
    if readout:
        C = trajectory.camera_to_world(opts.motion, t_rows)
        c = trajectory.position(opts.motion, t_rows)
    else:
        C = np.broadcast_to(trajectory.camera_to_world(opts.motion, t), (h, 3, 3))
        c = np.broadcast_to(trajectory.position(opts.motion, t), (h, 3))
    hits = cast(scene, rays, C, c, t_rows, opts.focal)
    flow = None
    if with_flow and k + 1 < opts.n_frames:
        t1 = t + 1.0 / opts.fps
        O1 = trajectory.orientation(opts.motion, t1)
        flow = ground_truth_flow(hits, K, O1, trajectory.position(opts.motion, t1), 1 / opts.fps)
    return hits.colour, flow


_WORKER: tuple = ()  # (opts, scene, with_flow) inherited by forked render workers


def _render_in_worker(k: int):
    opts, scene, with_flow = _WORKER
    return render_frame(opts, scene, k, with_flow=with_flow)


def render_frames(
    opts: SynthOptions,
    scene: Scene | None = None,
    *,
    with_flow: bool = False,
    workers: int | None = None,
) -> Iterator[tuple[NDArray[np.uint8], NDArray[np.float32] | None]]:
    """All frames in order (see :func:`render_frame`), rendered by ``workers`` processes.

    Frames are independent, so they render in parallel (default: one process per core,
    forked, so the scene is shared rather than copied); they still arrive in order.
    """
    global _WORKER
    if with_flow and opts.rolling_shutter_ms:
        raise ValueError("ground-truth flow needs a global shutter (rolling_shutter_ms=0)")
    scene = scene or build_scene(opts)
    workers = workers or min(os.cpu_count() or 1, 4)
    frames = range(opts.n_frames)
    if workers < 2 or opts.n_frames < 8 or "fork" not in mp.get_all_start_methods():
        for k in frames:
            yield render_frame(opts, scene, k, with_flow=with_flow)
        return
    _WORKER = (opts, scene, with_flow)
    # Chunks, two in flight so that no worker waits at a chunk's end, and a pool that is
    # closed and joined rather than terminated: terminating a Pool with tasks in flight
    # (a caller that takes only the first frame) can deadlock its task-handler thread,
    # and did, intermittently, in the test suite. Only the chunks in flight are held.
    pool = mp.get_context("fork").Pool(workers)
    chunks = iter([frames[i : i + 2 * workers] for i in range(0, len(frames), 2 * workers)])
    try:
        pending = deque(pool.map_async(_render_in_worker, c) for c in islice(chunks, 2))
        while pending:
            done = pending.popleft().get()
            pending.extend(pool.map_async(_render_in_worker, c) for c in islice(chunks, 1))
            yield from done
    finally:
        pool.close()
        pool.join()


def gyro_samples(opts: SynthOptions) -> tuple[NDArray, NDArray]:
    """(times on the gyro clock (s), rates (N, 3) in IMU axes) covering the clip."""
    rng = np.random.default_rng(opts.seed + 2)
    start, stop = -0.25, opts.n_frames / opts.fps + 0.25
    t = np.arange(start, stop, 1.0 / opts.gyro_rate)
    omega_cam = trajectory.angular_velocity(opts.motion, t)
    R = np.asarray(opts.r_cam_imu, dtype=np.float64)
    omega_imu = omega_cam @ R  # ω_imu = R_cam_imuᵀ ω_cam, row-wise
    omega_imu += np.asarray(opts.gyro_bias) + rng.normal(0, opts.gyro_noise, omega_imu.shape)
    return t + opts.gyro_offset, omega_imu


# What :func:`render_clip` writes into its folder
SYNTH_FILES = ("clip.mp4", "truth.csv", "truth.json", "gyro.csv", "timestamps.csv")


def write_truth(out: Path, opts: SynthOptions) -> None:
    t = clip_times(opts)
    O = trajectory.orientation(opts.motion, t)
    R = O[1:] @ np.swapaxes(O[:-1], -1, -2)
    rotvecs = so3.log_so3(R)
    quat = Rotation.from_matrix(O).as_quat(scalar_first=True)
    K = opts.K()
    with atomic_output(out / "truth.csv", overwrite=True) as tmp, open(tmp, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["frame", "t", "rx", "ry", "rz", "qw", "qx", "qy", "qz", "f", "cx", "cy"])
        for k in range(len(t)):
            rv = [f"{v:.12g}" for v in rotvecs[k]] if k < len(rotvecs) else ["", "", ""]
            q = [f"{v:.12g}" for v in quat[k]]
            writer.writerow([k, f"{t[k]:.9f}", *rv, *q, f"{K[0, 0]:.6f}", K[0, 2], K[1, 2]])
    g_t, g_w = gyro_samples(opts)
    with atomic_output(out / "gyro.csv", overwrite=True) as tmp, open(tmp, "w") as f:
        for (x, y, z), ts in zip(g_w, g_t, strict=True):
            f.write(f"{x:.9f},{y:.9f},{z:.9f},{round(ts * 1e9)}\n")
    with atomic_output(out / "timestamps.csv", overwrite=True) as tmp, open(tmp, "w") as f:
        for ts in t + opts.gyro_offset:
            f.write(f"{round(ts * 1e9)}\n")
    meta = asdict(opts)
    meta.update(
        n_frames=opts.n_frames,
        K=K.tolist(),
        focal_px=opts.focal,
        R_cam_imu=np.asarray(opts.r_cam_imu).tolist(),
        offset_s=opts.gyro_offset,
        conventions="../shared/CONVENTIONS.md: R_t = O_{t+1} O_t^T; offset = gyro - video clock",
    )
    (out / "truth.json").write_text(json.dumps(meta, indent=2))


def render_clip(
    out_dir: str | Path,
    opts: SynthOptions,
    progress: Callable[[int], None] | None = None,
) -> dict:
    """Render the clip and its truth into ``out_dir``; returns a summary."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_truth(out, opts)
    with atomic_output(out / "clip.mp4", overwrite=True) as tmp:
        tone = sine_audio(opts.n_frames / opts.fps)
        encoding = Encoding(crf=opts.crf, preset="veryfast")
        with FrameWriter(tmp, opts.size, opts.fps, encoding, tone) as writer:
            for frame, _ in render_frames(opts):
                writer.write(frame)
                if progress:
                    progress(1)
    R = trajectory.relative_rotations(opts.motion, clip_times(opts))
    return {
        "out_dir": str(out),
        "frames": opts.n_frames,
        "size": list(opts.size),
        "focal_px": opts.focal,
        "mean_rotation_deg": float(np.degrees(so3.angle(R)).mean()),
        "gyro_offset_s": opts.gyro_offset,
    }


__all__ = [
    "SYNTH_FILES",
    "SynthOptions",
    "build_scene",
    "render_clip",
    "render_frames",
    "write_truth",
]
