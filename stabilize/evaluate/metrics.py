"""The stabilisation literature's quality metrics, computed the same way for any tool.

* **Cropping ratio**: the mean scale of the registration from each original frame to
  the stabilised one (1 = nothing cropped; smaller = more zoom).
* **Distortion**: the worst frame's ratio of the smaller to the larger singular value of
  that registration's linear part (1 = no anisotropic stretch).
* **Stability** (Liu et al. 2013): the inter-frame motions of a clip, accumulated into a
  path; for its translation (mean of x and y) and its rotation, the share of spectral
  energy in the 2nd–6th FFT components, DC excluded. Higher is steadier. Reported
  separately and as the minimum of the two.
* **ITF**: the mean PSNR of consecutive frames, in dB.
* **Residual shake** (:mod:`stabilize.evaluate.shake`): the RMS of the high-passed
  frame-to-frame similarity motion, in px at the clip's width, and its in-plane rotation
  in degrees. What a viewer sees as shake; lower is steadier.
* **Wobble** (:mod:`stabilize.evaluate.wobble`): the RMS of the shear and stretch between
  consecutive frames (of the registration's linear part at the centre) that no
  similarity has, in px at the clip's width: a rolling shutter's jello. Lower is better.

Registrations are ORB features, spread evenly over a grid, matched with a ratio test
(between consecutive frames, each match then refined to a fraction of a pixel:
:func:`stabilize.evaluate.shake.subpixel`), then a RANSAC homography; frames with too few
features fall back to the identity (and are counted).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import asdict, dataclass, field

import cv2
import numpy as np
from numpy.typing import NDArray

from stabilize.evaluate.shake import (
    MIN_MATCHES,
    MIN_SPREAD,
    high_passed,
    matched_points,
    parts_of,
    principal_spread,
    residual_shake,
    similarity_motion,
    subpixel,
)
from stabilize.evaluate.wobble import non_similar_part, wobble
from stabilize.progress import Progress, no_progress

FEATURES = 2000  # ORB features per frame for registration
GRID = (6, 8)  # cells they are spread over
LOW_BAND = slice(1, 6)  # the 2nd to the 6th FFT components (index 0 is DC)
REGISTRATION_LONG_SIDE = 640


def registration_grey(
    frame: NDArray[np.uint8], long_side: int = REGISTRATION_LONG_SIDE
) -> NDArray[np.uint8]:
    """The frame in grey, shrunk to ``long_side`` px on its long side."""
    grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY) if frame.ndim == 3 else frame
    scale = long_side / max(grey.shape)
    if scale < 1:
        grey = cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    return grey


class Registrar:
    """Homographies between frames (ORB + ratio test + RANSAC), in the frames' pixels."""

    def __init__(self) -> None:
        self.orb = cv2.ORB_create(nfeatures=4 * FEATURES, fastThreshold=10)
        self.matcher = cv2.BFMatcher(cv2.NORM_HAMMING)
        self.failures = 0

    def features(self, frame: NDArray[np.uint8], grey: NDArray[np.uint8] | None = None):
        """(points in the frame's pixels, descriptors) of ORB features spread over
        ``frame``, found on ``grey``, its grey image at the registration's size
        (:func:`registration_grey`; made here if not given)."""
        grey = registration_grey(frame) if grey is None else grey
        scale = frame.shape[1] / grey.shape[1]
        kp = spread(self.orb.detect(grey, None), grey.shape)
        kp, desc = self.orb.compute(grey, kp)
        pts = np.float32([k.pt for k in kp]) * scale if kp else np.zeros((0, 2), np.float32)
        return pts, desc

    def homography(self, a, b, width: int) -> NDArray[np.float64]:
        """H with b ~ H a, from features() of two frames ``width`` px wide
        (:meth:`fit`)."""
        return self.fit(matched_points(a, b, self.matcher), width)

    def fit(self, matched: tuple[NDArray, NDArray] | None, width: int) -> NDArray[np.float64]:
        """H with dst ~ H src of matched points (src, dst) in frames ``width`` px wide;
        identity, counted as a failure, if it cannot be found, or if its inliers spread
        less than ``MIN_SPREAD`` of the width across their narrowest direction in either
        frame (a strip, which leaves the rest undetermined)."""
        if matched is not None:
            H, mask = cv2.findHomography(*matched, cv2.USAC_MAGSAC, 1.5)
            if H is not None and mask.sum() >= MIN_MATCHES:
                kept = mask.ravel() > 0
                narrowest = min(principal_spread(pts[kept])[0] for pts in matched)
                if narrowest >= MIN_SPREAD * width:
                    return H / H[2, 2]
        self.failures += 1
        return np.eye(3)


def spread(keypoints, shape: tuple[int, int], grid: tuple[int, int] = GRID) -> list:
    """The strongest keypoints of each cell of a grid, FEATURES in all.

    Left to itself ORB puts most of its features on the most textured thing in view,
    often a close moving subject; RANSAC then registers that subject instead of the
    scene. Spread over the frame, the features let the scene's motion win by area.
    """
    h, w = shape
    rows, cols = grid
    cells: dict[tuple[int, int], list] = {}
    for k in keypoints:
        key = (min(int(k.pt[1] * rows / h), rows - 1), min(int(k.pt[0] * cols / w), cols - 1))
        cells.setdefault(key, []).append(k)
    per_cell = max(1, FEATURES // (rows * cols))
    out = []
    for found in cells.values():
        out += sorted(found, key=lambda k: -k.response)[:per_cell]
    return out


def jacobian(H: NDArray, point: tuple[float, float]) -> NDArray:
    """The 2×2 local linear part of the homography H at a pixel."""
    x, y = point
    p = H @ [x, y, 1.0]
    return (H[:2, :2] * p[2] - np.outer(p[:2], H[2, :2])) / p[2] ** 2


def scale_and_distortion(
    H: NDArray, center: tuple[float, float] = (0.0, 0.0)
) -> tuple[float, float]:
    """Scale √|det A| and singular-value ratio σ_min/σ_max of A, H's linear part at
    ``center`` (the image centre: there a fitted homography's small perspective terms
    do not masquerade as stretch)."""
    s = np.linalg.svd(jacobian(H, center), compute_uv=False)
    return float(np.sqrt(s[0] * s[1])), float(s[1] / s[0])


STILL_PX = 0.05  # a path that moves less than this (RMS) is perfectly steady
STILL_RAD = 1e-4


def low_frequency_share(signal: NDArray, still: float = 0.0) -> float:
    """Energy share of the 2nd–6th FFT components of a signal, DC excluded.

    A signal whose RMS about its mean is below ``still`` scores 1: otherwise the
    registration's numerical noise on a motionless clip would decide its score.
    """
    if len(signal) < 8:
        return float("nan")
    signal = signal - signal.mean()
    if np.sqrt(np.mean(signal**2)) < still:
        return 1.0
    power = np.abs(np.fft.fft(signal)) ** 2
    power = power[: len(power) // 2 + 1]
    total = power[1:].sum()
    return float(power[LOW_BAND].sum() / total) if total > 0 else 1.0


def stability(inter_frame: list[NDArray]) -> tuple[float, float]:
    """(translation, rotation) stability of a path accumulated from inter-frame homographies."""
    path = []
    P = np.eye(3)
    for H in inter_frame:
        P = H @ P
        path.append(P / P[2, 2])
    path = np.array(path)
    if len(path) < 8:
        return float("nan"), float("nan")
    tx, ty = path[:, 0, 2], path[:, 1, 2]
    angle = np.unwrap(np.arctan2(path[:, 1, 0], path[:, 0, 0]))
    translation = 0.5 * (low_frequency_share(tx, STILL_PX) + low_frequency_share(ty, STILL_PX))
    return translation, low_frequency_share(angle, STILL_RAD)


def psnr(a: NDArray[np.uint8], b: NDArray[np.uint8]) -> float:
    mse = np.mean((a.astype(np.float32) - b.astype(np.float32)) ** 2)
    return float(10 * np.log10(255.0**2 / mse)) if mse > 0 else 100.0


@dataclass(frozen=True)
class ClipMetrics:
    frames: int
    cropping_ratio: float
    distortion: float
    stability_translation: float
    stability_rotation: float
    stability: float
    itf_db: float
    registration_failures: int
    residual_shake_px: float  # stabilize.evaluate.shake: RMS of the high-passed 2-D motion
    residual_shake_deg: float
    # the shake's parts (dx, dy, roll, zoom), px: what is left, and where the metric is noisy
    shake_components_px: tuple[float, float, float, float]
    wobble_px: float  # stabilize.evaluate.wobble: RMS shear and stretch between frames
    # per pair, what the residual shake is the RMS of (N-1, 4), and per frame the
    # distortion; for plots (stabilize.evaluate.plot), not in as_dict
    shake_series: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 4)))
    distortion_series: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    def as_dict(self) -> dict:
        """The figures (not the series)."""
        return {k: v for k, v in asdict(self).items() if not k.endswith("_series")}


class _Clip:
    """One clip's running inter-frame registrations and PSNRs, registered at
    ``long_side`` px."""

    def __init__(self, long_side: int = REGISTRATION_LONG_SIDE) -> None:
        self.long_side = long_side
        self.reg = Registrar()
        self.inter: list[NDArray] = []
        self.itf: list[float] = []
        # (features, grey, grey at the registration's size) of the last frame
        self.previous: tuple | None = None
        self.frames = 0
        self.motions: list[NDArray] = []  # frame-to-frame similarities (dx, dy, dθ, d ln s)
        self.skews: list[NDArray] = []  # their homographies' non-similar parts (wobble)
        self.shape: tuple[int, ...] = ()

    def add(self, frame: NDArray[np.uint8]):
        """Register a frame (RGB, or already grey) against the previous one; returns its
        features."""
        grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY) if frame.ndim == 3 else frame
        small = registration_grey(grey, self.long_side)  # (grey once: PSNR's, registration's)
        feat = self.reg.features(frame, small)
        if self.previous is not None:
            width = frame.shape[1]
            matched = matched_points(self.previous[0], feat, self.reg.matcher)  # once, for both
            if matched is not None:  # to a fraction of a pixel (:func:`subpixel`)
                matched = subpixel(self.previous[2], small, *matched, width / small.shape[1])
            self.inter.append(self.reg.fit(matched, width))
            motion = None if matched is None else similarity_motion(*matched, width)
            self.motions.append(np.zeros(4) if motion is None else motion)
            if not np.array_equal(self.inter[-1], np.eye(3)):  # registered
                centre = ((frame.shape[1] - 1) / 2, (frame.shape[0] - 1) / 2)
                self.skews.append(non_similar_part(jacobian(self.inter[-1], centre)))
            self.itf.append(psnr(self.previous[1], grey))
        self.previous = (feat, grey, small)
        self.frames += 1
        self.shape = frame.shape
        return feat

    def metrics(self, scales: list[float], ratios: list[float], fps: float) -> ClipMetrics:
        st, sr = stability(self.inter)
        h, w = self.shape[:2] if self.shape else (0, 0)
        motions, centre = np.array(self.motions).reshape(-1, 4), ((w - 1) / 2, (h - 1) / 2)
        series = high_passed(motions, w, fps, centre)
        parts = parts_of(series)
        shake = residual_shake(parts, w)
        return ClipMetrics(
            frames=self.frames,
            cropping_ratio=float(np.mean(scales)) if scales else 1.0,
            distortion=float(np.min(ratios)) if ratios else 1.0,
            stability_translation=st,
            stability_rotation=sr,
            stability=float(min(st, sr)),
            itf_db=float(np.mean(self.itf)) if self.itf else float("nan"),
            registration_failures=self.reg.failures,
            residual_shake_px=shake[0],
            residual_shake_deg=shake[1],
            shake_components_px=tuple(float(x) for x in parts),
            wobble_px=wobble(np.array(self.skews), w),
            shake_series=series,
            distortion_series=np.asarray(ratios, np.float64) if ratios else np.ones(self.frames),
        )


def evaluate_pair(
    original: Iterable[NDArray[np.uint8]],
    stabilised: Iterable[NDArray[np.uint8]],
    fps: float = 30.0,
    progress: Progress = no_progress,
) -> tuple[ClipMetrics, ClipMetrics]:
    """Metrics of the original and of the stabilised clip, in one pass over both;
    ``progress(1)`` after each pair of frames.

    Frames are taken in step; if one clip is longer, its extra frames are ignored.
    For the original, cropping ratio and distortion are 1 by definition.
    """
    before, (after,) = evaluate_against(original, [stabilised], fps, progress)
    return before, after


def evaluate_against(
    original: Iterable[NDArray[np.uint8]],
    outputs: Sequence[Iterable[NDArray[np.uint8]]],
    fps: float = 30.0,
    progress: Progress = no_progress,
) -> tuple[ClipMetrics, list[ClipMetrics]]:
    """Metrics of the original and of each of several outputs of it (two tools', say),
    in one pass that reads the original once; each output's are those
    :func:`evaluate_pair` gives it. Frames are taken in step; the shortest clip decides,
    and a clip longer than it by more than a frame is a ValueError: its frames are not
    the others' (a GIF of a 60 fps clip holds every other frame), and paired in step they
    gave figures of frames shot at other times."""
    before, afters = _Clip(), [_Clip() for _ in outputs]
    scales: list[list[float]] = [[] for _ in outputs]
    ratios: list[list[float]] = [[] for _ in outputs]
    counts = [0] * (1 + len(outputs))

    def counted(frames: Iterable[NDArray[np.uint8]], k: int) -> Iterator[NDArray[np.uint8]]:
        for frame in frames:
            counts[k] += 1
            yield frame

    clips = [counted(clip, k) for k, clip in enumerate((original, *outputs))]
    for orig, *stabs in zip(*clips, strict=False):
        feat_orig = before.add(orig)
        for after, stab, scale_k, ratio_k in zip(afters, stabs, scales, ratios, strict=True):
            feat_stab = after.add(stab)
            # Stabilised → original: a zoomed-in output registers with scale < 1.
            H = after.reg.homography(feat_stab, feat_orig, stab.shape[1])
            center = ((stab.shape[1] - 1) / 2, (stab.shape[0] - 1) / 2)
            scale, ratio = scale_and_distortion(H, center)
            scale_k.append(scale)
            ratio_k.append(ratio)
        progress(1)
    for clip in clips:  # what is left of the longer ones
        for _ in clip:
            pass
    if max(counts) - min(counts) > 1:
        said = ", ".join(f"{n} in output {k}" for k, n in enumerate(counts[1:], start=1))
        said = said if len(outputs) > 1 else f"{counts[1]} in the stabilised clip"
        raise ValueError(
            f"the clips hold different frames ({counts[0]} in the original, {said}): frames "
            "are compared in step, so each clip must hold every frame of the original"
        )
    mine = [a.metrics(s, r, fps) for a, s, r in zip(afters, scales, ratios, strict=True)]
    return before.metrics([], [], fps), mine


def evaluate(frames: Iterable[NDArray[np.uint8]], fps: float = 30.0) -> ClipMetrics:
    """Metrics of one clip on its own (cropping ratio and distortion are 1)."""
    clip = _Clip()
    for frame in frames:
        clip.add(frame)
    return clip.metrics([], [], fps)


# Mirrorings that keep every frame-to-frame motion's size (as index tuples of a frame):
# left-right, upside down, both.
_FLIP = slice(None, None, -1)
MIRRORS: dict[str, tuple[slice, ...]] = {
    "left-right": (slice(None), _FLIP),
    "upside down": (_FLIP,),
    "both": (_FLIP, _FLIP),
}


# The registration's other sizes that a finer spread reads at too (``shake_spread``'s
# ``sizes``): the pyramid's grid then falls elsewhere on the content, and a reading moves
# with it. On hero7 one lossless output read 0.822, 0.848, 0.870, 0.838 and 0.845 px at
# these five sizes (each the mean of four mirrored readings), so the 640 px mean of four
# carries an offset of about ±3% that more mirrors at 640 px cannot average out
SPREAD_SIZES = (576, 608, 640, 672, 704)


@dataclass(frozen=True)
class ShakeSpread:
    """A clip's residual shake (px) read as it is and under each of :data:`MIRRORS`, at
    the registration's size and, if asked, at others (:data:`SPREAD_SIZES`).

    Mirroring moves every feature but changes no motion's size, so the shake is the same;
    the registration's features and RANSAC's draws are not. The readings' range is the
    metric's own uncertainty on that clip, which a difference between two outputs must
    exceed to mean anything (4–12% of their mean on the GoPro and phone clips of the
    bench), and their mean a steadier reading than any one of them."""

    readings: tuple[float, ...]

    @property
    def mean(self) -> float:
        return float(np.mean(self.readings))

    def as_dict(self) -> dict:
        """The mean, the range and the readings (as it is first), px."""
        low, high = min(self.readings), max(self.readings)
        return {"mean": self.mean, "min": low, "max": high, "readings": list(self.readings)}


def shake_spread(
    frames: Iterable[NDArray[np.uint8]],
    as_it_is: float,
    fps: float = 30.0,
    progress: Progress = no_progress,
    sizes: Sequence[int] = (REGISTRATION_LONG_SIDE,),
) -> ShakeSpread:
    """The :class:`ShakeSpread` of a clip whose residual shake reads ``as_it_is`` (px): its
    frames registered at each size in ``sizes`` (the long side, px; by default the
    registration's own; a frame smaller than a size is read at its own), as they are and
    under every mirroring, in one pass, ``as_it_is`` standing for the registration's own
    size as it is; ``progress(1)`` after each frame. The readings: ``as_it_is``, then
    each size's in ``sizes``' order."""
    mirrors = [(slice(None),), *MIRRORS.values()]
    views = [
        (size, mirror)
        for size in sizes
        for mirror in mirrors
        if (size, mirror) != (REGISTRATION_LONG_SIDE, mirrors[0])  # as_it_is
    ]
    clips = [_Clip(size) for size, _ in views]
    for frame in frames:
        grey = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)  # once: a mirror's grey is grey's mirror
        for clip, (_, mirror) in zip(clips, views, strict=True):
            clip.add(np.ascontiguousarray(grey[mirror]))
        progress(1)
    readings = (as_it_is, *(c.metrics([], [], fps).residual_shake_px for c in clips))
    return ShakeSpread(tuple(float(r) for r in readings))
