"""The ``--report DIR`` files: rotations.csv, path.csv, trajectory.png, summary.json."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from rotation import so3
from stabilize.motion.files import write_rotations
from stabilize.video.atomic import atomic_folder
from stabilize.warp.camera_path import CameraPath

SHIFT_COLUMNS = ("shift_x", "shift_y", "shift_angle", "shift_scale")


def shift_in_pixels(planned: CameraPath) -> NDArray[np.float64]:
    """The 2-D correction after the turn, D_t (:mod:`stabilize.path.residual`), per frame
    (N, 4): how far it moves the content at the frame's middle (x right, y down, px at
    the input's size), its angle (degrees, clockwise on screen) and its scale. D_t is in
    normalised coordinates, so the move is f·(D₀₂, D₁₂), f each frame's focal length;
    (0, 0, 0, 1) where the warp undoes the turn alone (``--motion rotation``)."""
    n = len(planned.times)
    D = np.broadcast_to(np.eye(3), (n, 3, 3)) if planned.shift is None else planned.shift
    f = np.broadcast_to(np.asarray(planned.K)[..., 0, 0], (n,))
    angle = np.degrees(np.arctan2(D[:, 1, 0], D[:, 0, 0]))
    return np.c_[D[:, :2, 2] * f[:, None], angle, np.hypot(D[:, 0, 0], D[:, 1, 0])]


def write_path(path: Path, planned: CameraPath) -> None:
    """Per frame: t, raw and smoothed orientation (w,x,y,z), zoom, homography (9 entries),
    the shot it belongs to (0 up to its first cut), and the 2-D correction after the turn
    (:func:`shift_in_pixels`)."""
    raw = Rotation.from_matrix(planned.raw).as_quat(scalar_first=True)
    smooth = Rotation.from_matrix(planned.smooth).as_quat(scalar_first=True)
    shot = np.searchsorted(planned.shots, np.arange(len(planned.times)), side="right") - 1
    shift = shift_in_pixels(planned)
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
                *SHIFT_COLUMNS,
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
                    *(f"{v:.6f}" for v in shift[k]),
                ]
            )


def plot_trajectory(path: Path, planned: CameraPath) -> None:
    """Raw against smoothed pitch, yaw and roll (the camera's own rotation, degrees), and
    the zoom; beside them, where the warp makes one, the 2-D correction after the turn
    (:func:`shift_in_pixels`). Each shot's own path, an edited clip's cuts dashed
    between them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # The camera's own orientation is Oᵀ; its rotation vector is (pitch, yaw, roll).
    raw = np.degrees(so3.log_so3(np.swapaxes(planned.raw, -1, -2)))
    smooth = np.degrees(so3.log_so3(np.swapaxes(planned.smooth, -1, -2)))
    # a planned path jumps at a cut, where no camera moved: its line is broken there
    starts = np.array(planned.shots[1:], dtype=int)

    def broken(values: NDArray) -> NDArray:
        return np.insert(values, starts, np.nan, axis=0)

    times = broken(planned.times)
    cuts = (planned.times[starts] + planned.times[starts - 1]) / 2
    shift = shift_in_pixels(planned)
    two_d = not np.allclose(shift, [0.0, 0.0, 0.0, 1.0], atol=1e-9)  # --motion rotation: none
    columns = 2 if two_d else 1
    fig, axes = plt.subplots(4, columns, figsize=(10 * columns, 9), sharex=True, squeeze=False)
    turn = axes[:, 0]
    for ax, k, name in zip(turn, (1, 0, 2), ("yaw (°)", "pitch (°)", "roll (°)"), strict=False):
        ax.plot(planned.times, raw[:, k], lw=1, color="0.55", label="raw")
        ax.plot(times, broken(smooth[:, k]), lw=2, color="C0", label="smoothed")
        ax.set_ylabel(name)
    turn[3].plot(times, broken(planned.zoom), color="C3")
    turn[3].set_ylabel("zoom")
    if two_d:
        names = ("x (px)", "y (px)", "angle (°)", "scale")
        for k, (ax, name) in enumerate(zip(axes[:, 1], names, strict=True)):
            ax.plot(times, broken(shift[:, k]), color="C2")
            ax.set_ylabel(name)
        turn[0].set_title("the camera's turn")
        axes[0, 1].set_title("the 2-D correction after the turn (the frame's middle moved)")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        for at, t in enumerate(cuts):
            ax.axvline(t, color="0.3", ls="--", lw=1, label=None if at else "cut")
    axes[0, 0].legend(loc="upper left")
    for ax in axes[3]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Camera path: raw and smoothed")
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
