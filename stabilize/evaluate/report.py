"""The ``--report DIR`` files: rotations.csv, path.csv, trajectory.png, summary.json."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from rotation import so3
from stabilize.motion.files import write_rotations
from stabilize.video.atomic import atomic_folder
from stabilize.warp.camera_path import CameraPath


def write_path(path: Path, planned: CameraPath) -> None:
    """Per frame: t, raw and smoothed orientation (w,x,y,z), zoom, homography (9 entries),
    and the shot it belongs to (0 up to its first cut)."""
    raw = Rotation.from_matrix(planned.raw).as_quat(scalar_first=True)
    smooth = Rotation.from_matrix(planned.smooth).as_quat(scalar_first=True)
    shot = np.searchsorted(planned.shots, np.arange(len(planned.times)), side="right") - 1
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(
            [
                "frame",
                "t",
                "raw_w",
                "raw_x",
                "raw_y",
                "raw_z",
                "smooth_w",
                "smooth_x",
                "smooth_y",
                "smooth_z",
                "zoom",
                *(f"h{i}{j}" for i in range(3) for j in range(3)),
                "shot",
            ]
        )
        for k, t in enumerate(planned.times):
            writer.writerow(
                [
                    k,
                    f"{t:.6f}",
                    *(f"{v:.9f}" for v in raw[k]),
                    *(f"{v:.9f}" for v in smooth[k]),
                    f"{planned.zoom[k]:.6f}",
                    *(f"{v:.9g}" for v in planned.homographies[k].ravel()),
                    shot[k],
                ]
            )


def plot_trajectory(path: Path, planned: CameraPath) -> None:
    """Raw against smoothed pitch, yaw and roll (the camera's own rotation, degrees), and
    the zoom; each shot's own path, an edited clip's cuts dashed between them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # The camera's own orientation is Oᵀ; its rotation vector is (pitch, yaw, roll).
    raw = np.degrees(so3.log_so3(np.swapaxes(planned.raw, -1, -2)))
    smooth = np.degrees(so3.log_so3(np.swapaxes(planned.smooth, -1, -2)))
    # a planned path jumps at a cut, where no camera moved: its line is broken there
    starts = np.array(planned.shots[1:], dtype=int)
    times = np.insert(planned.times, starts, np.nan)
    smooth = np.insert(smooth, starts, np.nan, axis=0)
    zoom = np.insert(planned.zoom, starts, np.nan)
    cuts = (planned.times[starts] + planned.times[starts - 1]) / 2
    fig, axes = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    for ax, k, name in zip(axes, (1, 0, 2), ("yaw", "pitch", "roll"), strict=False):
        ax.plot(planned.times, raw[:, k], lw=1, color="0.55", label="raw")
        ax.plot(times, smooth[:, k], lw=2, color="C0", label="smoothed")
        ax.set_ylabel(f"{name} (°)")
        ax.grid(alpha=0.3)
    for ax in axes:
        for at, t in enumerate(cuts):
            ax.axvline(t, color="0.3", ls="--", lw=1, label=None if at else "cut")
    axes[0].legend(loc="upper left")
    axes[3].plot(times, zoom, color="C3")
    axes[3].set_ylabel("zoom")
    axes[3].set_xlabel("time (s)")
    axes[3].grid(alpha=0.3)
    fig.suptitle("Camera orientation: raw and smoothed")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_report(folder: str | Path, planned: CameraPath, summary: dict) -> None:
    """The run's report folder: rotations.csv, path.csv, trajectory.png, summary.json."""
    with atomic_folder(folder) as tmp:  # all four from this run, or the old ones kept
        rotvecs = so3.log_so3(planned.rotations)
        cuts = np.zeros(len(rotvecs), bool)
        cuts[np.array(planned.shots[1:], dtype=int) - 1] = True  # where the plan restarts
        rows = (planned.times[:-1], rotvecs, planned.support, cuts)
        write_rotations(tmp / "rotations.csv", *rows)
        write_path(tmp / "path.csv", planned)
        plot_trajectory(tmp / "trajectory.png", planned)
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2))
