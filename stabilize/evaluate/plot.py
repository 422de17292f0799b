"""The evaluation as a picture: what is left of the shake, frame by frame.

For the original and the stabilised clip, each part of the high-passed frame-to-frame
motion (:func:`stabilize.evaluate.shake.high_passed`: x, y, roll and zoom, in px at the
clip's width) over time, and the stabilised clip's distortion per frame. Where a part
stays large, or both clips peak together, the picture shows it; a table cannot.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stabilize.evaluate.metrics import ClipMetrics

PARTS = ("x", "y", "roll", "zoom")


def plot_shake(
    path: str | Path, original: ClipMetrics, stabilised: ClipMetrics, fps: float
) -> None:
    """A PNG at ``path``: the shake's four parts of both clips, and the distortion."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(5, 1, figsize=(10, 11), sharex=True)
    for clip, colour, width, metrics in (
        ("original", "0.6", 1.0, original),
        ("stabilised", "C0", 1.4, stabilised),
    ):
        series = metrics.shake_series
        t = (np.arange(len(series)) + 0.5) / fps  # a pair sits between its two frames
        for k, ax in enumerate(axes[:4]):
            rms = metrics.shake_components_px[k]
            ax.plot(t, series[:, k], lw=width, color=colour, label=f"{clip}: RMS {rms:.2f} px")
    for k, ax in enumerate(axes[:4]):
        ax.set_ylabel(f"{PARTS[k]} (px)")
        ax.axhline(0.0, color="0.3", lw=0.5)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.3)
    ratios = stabilised.distortion_series
    axes[4].plot(np.arange(len(ratios)) / fps, ratios, color="C3")
    axes[4].set_ylabel("distortion")
    axes[4].set_xlabel("time (s)")
    axes[4].grid(alpha=0.3)
    fig.suptitle(
        f"Residual shake: {original.residual_shake_px:.3f} px original, "
        f"{stabilised.residual_shake_px:.3f} px stabilised (high-passed at 0.5 s); "
        f"worst distortion {stabilised.distortion:.3f}"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
