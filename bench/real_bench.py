"""Real footage: ours against FFmpeg's vid.stab on every real clip in ../shared/data (and
phone-cc9 zoomed in to 31°), and on rendered walks at fields of view the tool is not told.

Each clip is stabilised by both tools with the same encoder (libx264, CRF 18, preset
medium; see ``stabilize_bench.py``), and the table gives, for the original and for each
output, the residual shake (``stabilize evaluate``: the RMS of the high-passed
frame-to-frame similarity motion, px at the clip's width) and its parts (x, y, roll,
zoom: on a walk past near surfaces the zoom is the metric's noisiest), the wobble (a rolling
shutter's shear and stretch between frames, px), stability, cropping,
distortion and wall time, then the median of ours ÷ vid.stab's residual shake. Each
output's shake plot (``stabilize evaluate --plot``) is left beside it.

The ``crop only`` row is the original's middle at vid.stab's crop, scaled back to the
frame, not stabilised: what the crop alone does to the metric, the reading a tool that
only zoomed in would get. Cropping changes which features the registration sees; on
hero7, a forward walk past near surfaces, it moved the zoom part from 1.29 to 1.06 px
with no motion changed, and a crop window 31–55 px off the middle read 0.95–1.16.

The last column splits the zoom part on such walks: how many frames' high-passed zoom
exceeds ``JUMP_PX`` (the registration jumping from one depth layer to the other between
pairs: on hero7 the near plants loom about 5 px a frame, the far scene about 0), and the
zoom part of the other frames. On hero7 ours jumps in 31 frames, vid.stab's output in 16,
the crop alone in 21 and the original in 42; the other frames read 0.89 px in ours and
0.86 in vid.stab's, so the jumps are most of the gap between the two.

``--spread`` also reads each output mirrored left-right, upside down and both: the same
motion, so the same shake, but other features and other RANSAC draws. The range of the
four readings is the metric's own uncertainty on that clip, which a difference between
the tools must exceed to mean anything (max-heromode: ours 0.921–0.988, vid.stab
0.944–1.009; hero7: 1.305–1.335 against 1.118–1.194), and their mean a steadier reading;
the median ratio is then given of the means too. With ``--sizes`` each output is also read
so at the registration's four other sizes (576–704 px on the long side, not 640 only):
20 readings, whose mean no longer carries the offset of where the pyramid's grid falls
on the content (±3% on hero7). (The figures quoted here were read before
the registration was refined to a fraction of a pixel, on 7 December; docs/real-footage.md
gives that day's bench read both ways, and the README the current run.)

``--out-crf`` sets the CRF both tools' output (and the crop) is encoded at (18, as our
default encodes it). At 0 the encode is lossless and the rows read the geometry alone:
x264 answers a change of one grey level in a few pixels with other decisions across the
frame, and the metric follows them. On hero7 two builds whose focal lengths differed by
5e-13 px (their homographies within 2e-7 of each other) wrote outputs 0.54 grey levels
apart on average, which read 1.192 and 1.207 px (mirrored means 1.204 and 1.256);
losslessly both read 1.260 (at the 3 px gate of the time: docs/focal-length.md).

    python bench/real_bench.py                 # the real clips and three rendered walks
    python bench/real_bench.py --fov auto      # our run with the focal length estimated
    python bench/real_bench.py --spread        # with the metric's spread on each output
    python bench/real_bench.py --spread --sizes   # 20 readings each: slower, finer
    python bench/real_bench.py --out-crf 0     # both outputs lossless: the geometry alone
    python bench/real_bench.py clip.mp4 ...    # other clips
    python bench/real_bench.py --width 640     # each clip scaled down first (640×360)
    python bench/real_bench.py --zoom 2        # each clip's middle half, at its own size
    python bench/real_bench.py --portrait      # each clip's middle 9:16, upright
    python bench/real_bench.py --turned        # each clip turned a quarter, baked in
    python bench/real_bench.py --every 2       # every other frame, at half the rate
    python bench/real_bench.py --crf 32        # each clip compressed as a shared clip is
    python bench/real_bench.py --rotation 90   # each clip tagged as a phone held upright
    python bench/real_bench.py --grain 22      # each clip dim and grainy, as in low light
    python bench/real_bench.py --measured      # and the metric's own readings undone
    python bench/real_bench.py --equal-crop    # and ours again at vid.stab's crop

``--width`` scales every clip down (FFmpeg, bicubic, CRF 14, limited range) before either
tool sees it: the literature's "Regular" clips are 640×360, and there the lead is
smaller (docs/real-footage.md). ``--zoom`` keeps the middle 1/Z of each side instead, scaled back to
the clip's size (or to ``--width``), as a digital zoom does: a narrower field of view
that no tool is told, where a wrong focal length shows most. ``--portrait`` keeps each
clip's middle 9:16 of its height first: a clip shot upright and stored upright (an
editor's or a messenger's copy, with no display rotation), whose default field of view
spans its height. ``--every 2`` keeps every other
frame, at half the rate: twice the motion a pair, as a walk at 15 fps, or past nearer
surfaces, would show. ``--crf 32`` encodes each view as coarsely as a clip shared on the
web often is (each view is otherwise CRF 14). ``--rotation 90`` tags each view with that
display rotation, the stream copied: a phone held upright stores its frames level, with
its sensor's rows in readout order, and asks the player to turn them (the content then
shows on its side, which neither tool nor the metric minds). ``--grain 22`` dims each
view (contrast 0.55, brightness −0.22) and adds temporal noise of that strength (FFmpeg's
``noise`` filter, its default seed, so every run sees the same grain): a clip shot in
low light, whose sensor noise the flow sees frame by frame.
``--turned`` turns each clip a quarter clockwise and stores it so, with no display
rotation: a messenger's or an editor's copy of a clip shot with the phone upright, whose
sensor's rows (read out one after another under a rolling shutter) now run down the
frame's columns, where the tool's readout model expects rows.

``--measured`` adds a row: the original with the high-passed motion the metric reads on
it undone frame by frame, at vid.stab's crop (:func:`measured_undone`). Where the
registration's own readings are noisy, undoing them adds their noise: on hero7, karma,
max-heromode and phone-cc9's frames the row's zoom part reads 26–58% above the crop
alone's, so what the metric reads as zoom there is mostly its own noise
(docs/real-footage.md).

``--equal-crop`` adds a row: ours again at vid.stab's crop, its ``--max-zoom`` (in the
row's name) scaled from the default until its cropping ratio lies within 0.005 of
vid.stab's (:func:`at_crop`), and the median ratio at that crop. The issue compares the
tools at equal crop (±0.01); at the defaults ours crops lighter where its 2-D correction
zooms out (cockatoo 0.882 against 0.871, hero7 0.885 against 0.870). Where the budget
does not bind (phone-cc9's frames, the 100° walk), ours keeps the lighter crop its path
needs, and the row reads as the default run.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from stabilize_bench import OUT_CRF, crf_option, encoder, timed, vidstab

from stabilize.evaluate.metrics import (
    REGISTRATION_LONG_SIDE,
    SPREAD_SIZES,
    evaluate,
    evaluate_against,
    evaluate_pair,
    shake_spread,
)
from stabilize.evaluate.plot import plot_shake
from stabilize.settings import Settings
from stabilize.video import ffmpeg_exe, probe, read_frames

if TYPE_CHECKING:
    from stabilize.evaluate.metrics import ClipMetrics
    from stabilize.synth import SynthOptions

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
REAL = ("handheld/cockatoo.mp4", "gopro/karma.mp4", "gopro/hero7.mp4", "gopro/max-heromode.mp4")
VIEW_CRF = 14  # each view's encoding: close to its source
CROP_MATCH = 0.005  # the issue asks for equal crop within ±0.01: half that, to be safe
CROP_TRIES = 3  # runs of ours at a scaled --max-zoom before the nearest is taken
# a run whose crop moves less than this from the last one's: the budget does not bind
# (phone-cc9's frames and the 100° walk crop 0.886 and 0.907 at a budget of 1.15 or 1.25)
CROP_STILL = 0.002
JUMP_PX = 2.0  # a frame's high-passed zoom beyond this is a jump between depth layers
RENDERED_FOV = (30.0, 45.0, 100.0)  # walks past near walls, at these unknown fields of view
WALK = 1.4  # m/s, the rendered walks' pace
# phone-cc9 zoomed in, as a phone's digital zoom does: its frames' middle 320×240 about the
# principal point (406.01, 309.01), shown at 640×480: a real 31° clip whose f is known
# (2 × 573.85 px), the kind of narrow clip (a zoo, a stage) where a wrong f shows most
ZOOM_CROP = "crop=320:240:246:189,scale=640:480"
PHONE = SHARED / "phone-cc9" / "frames"


def phone_clip(out: Path, view: str | None = None, crf: int = 12) -> Path:
    """phone-cc9's frames as an H.264 clip (at ``crf``) at ``out``, through the FFmpeg
    filter ``view`` where given."""
    pattern = ["-framerate", "30", "-start_number", "99", "-i", str(PHONE / "RE_frame-%d.jpg")]
    cmd = [ffmpeg_exe(), "-v", "error", "-y", *pattern, *(["-vf", view] if view else [])]
    subprocess.run(
        [*cmd, "-c:v", "libx264", "-crf", str(crf), "-pix_fmt", "yuv420p", str(out)], check=True
    )
    return out


def clips(work: Path) -> list[Path]:
    """The real clips, phone-cc9's frames as a clip and zoomed in, and the rendered
    walks."""
    found = [SHARED / name for name in REAL if (SHARED / name).is_file()]
    if PHONE.is_dir():
        found.append(phone_clip(work / "phone-cc9.mp4"))
        found.append(phone_clip(work / "phone-cc9-zoom31.mp4", ZOOM_CROP))
    from stabilize.synth import render_clip

    for fov in RENDERED_FOV:
        folder = work / f"walk{int(fov)}"
        render_clip(folder, walk_options(fov))
        found.append(folder / "clip.mp4")
    return found


def walk_options(fov: float) -> SynthOptions:
    """The rendered walk past near walls at ``fov`` (SynthOptions: 540×960, 4 s, at
    ``WALK`` m/s, seeded by its field of view)."""
    from stabilize.synth import SynthOptions

    return SynthOptions(seed=int(fov), seconds=4.0, hfov=fov, walk=WALK)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("clips", nargs="*", type=Path)
    parser.add_argument("--fov", help="passed to our run (e.g. auto)")
    parser.add_argument("--spread", action="store_true", help="read each output mirrored too")
    parser.add_argument(
        "--sizes",
        action="store_true",
        help="with --spread, read at the registration's five sizes too (20 readings)",
    )
    parser.add_argument("--width", type=int, help="scale each clip down to this width first")
    parser.add_argument("--zoom", type=float, help="keep each clip's middle 1/ZOOM first")
    parser.add_argument(
        "--portrait", action="store_true", help="keep each clip's middle 9:16 first (upright)"
    )
    parser.add_argument(
        "--turned", action="store_true", help="turn each clip a quarter clockwise, baked in"
    )
    parser.add_argument("--every", type=int, default=1, help="keep every EVERY-th frame first")
    parser.add_argument(
        "--crf", type=crf_option, default=VIEW_CRF, help="encode each view at this CRF"
    )
    parser.add_argument(
        "--out-crf", type=crf_option, default=OUT_CRF, help="encode both tools' output at this CRF"
    )
    parser.add_argument(
        "--rotation", type=int, default=0, choices=(0, 90, 180, 270), help="tag each view so"
    )
    parser.add_argument(
        "--grain", type=int, default=0, help="dim each view and add noise this strong (0-100)"
    )
    parser.add_argument(
        "--equal-crop",
        action="store_true",
        help="also ours run again with --max-zoom set so that it crops as vid.stab does",
    )
    parser.add_argument(
        "--measured",
        action="store_true",
        help="also the original with the shake the metric measures on it undone",
    )
    args = parser.parse_args()
    if args.sizes and not args.spread:
        parser.error("--sizes reads the spread: give --spread too")
    sizes = SPREAD_SIZES if args.sizes else (REGISTRATION_LONG_SIDE,)
    if args.width is not None and args.width < 16:
        parser.error("--width must be at least 16 px")
    if args.zoom is not None and not 1 <= args.zoom <= 8:
        parser.error("--zoom must be between 1 and 8")
    if not 1 <= args.every <= 8:
        parser.error("--every must be between 1 and 8")
    if not 0 <= args.grain <= 100:
        parser.error("--grain must be between 0 and 100")
    view = View(
        width=args.width,
        zoom=args.zoom or 1.0,
        portrait=args.portrait,
        every=args.every,
        crf=args.crf,
        rotation=args.rotation,
        grain=args.grain,
        turned=args.turned,
    )
    work = Path(tempfile.mkdtemp(prefix="real-bench-"))
    ratios, mean_ratios, equal_ratios, equal_mean_ratios = [], [], [], []
    header = (
        f"{'clip':28s}{'tool':10s}{'shake px':>9s}{'wobble':>7s}{'stab':>7s}{'crop':>7s}"
        f"{'dist':>7s}{'s':>7s}   x / y / roll / zoom px   zoom jumps / the rest"
    )
    print(header)
    for given in args.clips or clips(work):
        name = f"{given.parent.name}/{given.name}"[-27:]
        tag = f"{given.parent.name}_{given.stem}"  # the rendered walks are all clip.mp4
        clip = viewed(given, work / f"{tag}_view.mp4", view)
        info = probe(clip)
        mine, theirs = work / f"{tag}_ours.mp4", work / f"{tag}_vidstab.mp4"
        cmd = [sys.executable, "-m", "stabilize.cli", "run", str(clip), str(mine), "-q"]
        cmd += [
            "--overwrite",
            "--crf",
            str(args.out_crf),
            *(["--fov", args.fov] if args.fov else []),
        ]
        t_ours, _ = timed(cmd)
        t_vs, _ = vidstab(clip, theirs, work, args.out_crf)
        fps = info.fps or 30.0
        outputs = [read_frames(mine, info.size), read_frames(theirs, info.size)]
        original, (ours_m, theirs_m) = evaluate_against(read_frames(clip), outputs, fps)
        for tool, m in (("ours", ours_m), ("vidstab", theirs_m)):  # what each row is the RMS of
            plot_shake(work / f"{tag}_{tool}_shake.png", original, m, fps)
        crop = crop_only(
            clip, work / f"{tag}_crop.mp4", theirs_m.cropping_ratio, info.size, args.out_crf
        )
        _, crop_m = evaluate_pair(read_frames(clip), read_frames(crop, info.size), fps)
        reference = [("original", original, None), ("crop only", crop_m, None)]
        if args.measured:
            undone = measured_undone(
                clip,
                work / f"{tag}_measured.mp4",
                theirs_m.cropping_ratio,
                info.size,
                fps,
                args.out_crf,
            )
            _, undone_m = evaluate_pair(read_frames(clip), read_frames(undone, info.size), fps)
            reference.append(("measured", undone_m, None))
        for tool, m, t in (
            *reference,
            ("ours", ours_m, t_ours),
            ("vid.stab", theirs_m, t_vs),
        ):
            print(_row(name, tool, m, t))
        ratios.append(ours_m.residual_shake_px / theirs_m.residual_shake_px)
        found = None
        if args.equal_crop:
            default = AtCrop(Settings().max_zoom, ours_m, t_ours, mine)
            found = at_crop(cmd, clip, info.size, fps, default, theirs_m.cropping_ratio)
            print(_row(name, f"ours {found.max_zoom:.3f}", found.metrics, found.seconds))
            equal_ratios.append(found.metrics.residual_shake_px / theirs_m.residual_shake_px)
        if args.spread:
            mine_all = mirrored(mine, info.size, fps, ours_m, sizes)
            theirs_all = mirrored(theirs, info.size, fps, theirs_m, sizes)
            print(f"{'':28s}{'mirrored':10s}ours {span(mine_all)}, vid.stab {span(theirs_all)}")
            mean_ratios.append(np.mean(mine_all) / np.mean(theirs_all))
            if found is not None:
                found_all = (
                    mine_all
                    if found.path == mine
                    else mirrored(found.path, info.size, fps, found.metrics, sizes)
                )
                print(f"{'':28s}{'mirrored':10s}ours at vid.stab's crop {span(found_all)}")
                equal_mean_ratios.append(np.mean(found_all) / np.mean(theirs_all))
    print(f"\nours ÷ vid.stab residual shake: {medians(ratios)}; outputs and shake plots in {work}")
    for label, found_ratios in (
        ("ours at vid.stab's crop", equal_ratios),
        ("of the readings' means", mean_ratios),
        ("of the readings' means, ours at vid.stab's crop", equal_mean_ratios),
    ):
        if found_ratios:
            print(f"the same, {label}: {medians(found_ratios)}")


def medians(ratios: list[float]) -> str:
    """The ratios' median, and each of them."""
    return f"median {statistics.median(ratios):.2f} ({', '.join(f'{r:.2f}' for r in ratios)})"


@dataclass(frozen=True)
class View:
    """How the bench sees a clip: with ``portrait`` its middle 9:16 of the frame's height
    (a clip stored upright: its long side is its height), then the middle
    1/``zoom`` of each side, scaled to ``width`` (its aspect kept, even sides; None: its
    own width, never up from there), turned a quarter clockwise where ``turned`` (baked
    in), every ``every``-th frame at 1/``every`` the rate, dimmed with temporal noise of
    strength ``grain`` (0: none; FFmpeg's ``noise``), encoded at ``crf`` (x264), then
    tagged to be shown turned ``rotation``°."""

    width: int | None = None
    zoom: float = 1.0
    portrait: bool = False
    every: int = 1
    crf: int = VIEW_CRF
    rotation: int = 0
    grain: int = 0
    turned: bool = False


# A dim view's levels (FFmpeg's eq): its grain then stands out as a low-light clip's does
DIM = "eq=brightness=-0.22:contrast=0.55"


def viewed(clip: Path, dst: Path, view: View) -> Path:
    """``clip``'s video as ``view`` sees it, at ``dst`` (``clip`` itself where it sees
    all of it)."""
    info = probe(clip)
    w, h = info.width, info.height
    upright = ""
    if view.portrait and w > h * 9 / 16:
        w = 2 * round(h * 9 / 32)  # even
        upright = f"crop={w}:{h},"
    out = min(view.width or w, w)
    level = dst.with_name(f"{dst.stem}_level{dst.suffix}") if view.rotation else dst
    if replace(view, rotation=0) == View(width=view.width) and out == w:
        level = clip  # nothing to change but the tag, if any: the clip itself
    else:
        crop = f"{middle(w, h, 1 / view.zoom)}," if view.zoom != 1.0 else ""
        rate = (info.fps or 30.0) / view.every
        every = view.every
        sparse = f"select=not(mod(n\\,{every})),setpts=N/({rate}*TB)," if every > 1 else ""
        chain = f"{sparse}{upright}{crop}scale={out}:-2:flags=bicubic"
        chain += ",transpose=clock" if view.turned else ""
        chain += f",{DIM},noise=alls={view.grain}:allf=t+u" if view.grain else ""
        cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(clip), "-map", "0:v:0", "-vf", chain]
        codec = ["-r", f"{rate}", "-c:v", "libx264", "-crf", str(view.crf)]
        codec += ["-pix_fmt", "yuv420p", "-an"]
        subprocess.run([*cmd, *codec, str(level)], check=True)
    if not view.rotation:
        return level
    tag = [ffmpeg_exe(), "-v", "error", "-y", "-display_rotation", str(view.rotation)]
    subprocess.run([*tag, "-i", str(level), "-map", "0:v:0", "-c", "copy", str(dst)], check=True)
    return dst


def middle(width: int, height: int, ratio: float) -> str:
    """FFmpeg's crop filter for the middle ``ratio`` of each side of a frame (even sides)."""
    cw, ch = 2 * round(width * ratio / 2), 2 * round(height * ratio / 2)
    return f"crop={cw}:{ch}:{(width - cw) // 2}:{(height - ch) // 2}"


def crop_only(clip: Path, dst: Path, ratio: float, size: tuple[int, int], crf: int) -> Path:
    """``clip``'s middle, ``ratio`` of each side, scaled back to ``size`` (h, w), encoded as
    both tools' output is (x264 at ``crf``): the crop without the stabilisation."""
    h, w = size
    view = f"{middle(w, h, ratio)},scale={w}:{h}:flags=bicubic"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(clip), "-vf", view, *encoder(crf), "-an"]
    subprocess.run([*cmd, str(dst)], check=True)
    return dst


def measured_undone(
    clip: Path, dst: Path, ratio: float, size: tuple[int, int], fps: float, crf: int
) -> Path:
    """``clip`` with the shake the metric measures on it undone, at ``dst``: frame t moved
    by the similarity -Σ_{k<t} h_k, h_k the high-passed frame-to-frame motion the metric
    reads on the original (``shake_series``: dx, dy at the frame's middle, roll and zoom in
    px at the width), about the frame's middle, then cropped to ``ratio`` as
    :func:`crop_only` is and encoded as both tools' output is. What a 2-D stabiliser that
    knew the metric's own readings would make of the clip: where the registration's
    readings are themselves noisy, undoing them adds that noise."""
    h, w = size
    shake = evaluate(read_frames(clip, size), fps).shake_series
    undo = np.vstack([np.zeros(4), -np.cumsum(shake, axis=0)])
    middle_px = np.array([(w - 1) / 2, (h - 1) / 2])
    source = ["-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}", "-r", f"{fps}", "-i", "-"]
    cmd = [ffmpeg_exe(), "-v", "error", "-y", *source, *encoder(crf), str(dst)]
    with subprocess.Popen(cmd, stdin=subprocess.PIPE) as pipe:
        assert pipe.stdin is not None
        for frame, (dx, dy, roll, zoom) in zip(read_frames(clip, size), undo, strict=False):
            angle, scale = roll * 2 / w, np.exp(zoom * 2 / w) / ratio
            c, s = scale * np.cos(angle), scale * np.sin(angle)
            A = np.array([[c, -s], [s, c]])  # about the middle, then the crop's zoom
            shift = middle_px - A @ middle_px + np.array([dx, dy]) / ratio
            warped = cv2.warpAffine(
                frame, np.c_[A, shift], (w, h), borderMode=cv2.BORDER_REFLECT_101
            )
            pipe.stdin.write(np.ascontiguousarray(warped).tobytes())
        pipe.stdin.close()
    if pipe.returncode:
        raise RuntimeError(f"FFmpeg failed writing {dst}")
    return dst


@dataclass(frozen=True)
class AtCrop:
    """Our run at vid.stab's crop: the ``--max-zoom`` that got there, its metrics, its
    wall time and its output."""

    max_zoom: float
    metrics: ClipMetrics
    seconds: float
    path: Path


def at_crop(
    cmd: list[str], clip: Path, size: tuple[int, int], fps: float, ours: AtCrop, crop: float
) -> AtCrop:
    """Our run of ``clip`` (frames of ``size``; ``cmd``; ``ours``: at the default budget)
    again with ``--max-zoom`` scaled until its cropping ratio lies within ``CROP_MATCH``
    of ``crop`` (vid.stab's), at most ``CROP_TRIES`` runs, the nearest kept: the issue's
    comparison at equal crop. Our mean crop is lighter than the budget's 1/max-zoom where
    the 2-D correction zooms out (it never zooms in: the zoom alone spends the budget),
    while vid.stab's static zoom crops every frame alike. Each run scales the budget by
    the ratio of the crops, as if the crop went as 1/max-zoom, which holds where the
    budget binds. Where it does not, a larger budget changes nothing: ours keeps the
    lighter crop its path needs."""
    tried = [ours]
    for k in range(CROP_TRIES):
        last = tried[-1]
        if abs(last.metrics.cropping_ratio - crop) <= CROP_MATCH:
            break
        out = ours.path.with_name(f"{ours.path.stem}_at_crop{k}{ours.path.suffix}")
        run = [str(out) if part == str(ours.path) else part for part in cmd]
        max_zoom = last.max_zoom * last.metrics.cropping_ratio / crop
        seconds, _ = timed([*run, "--max-zoom", f"{max_zoom:.4f}"])
        _, metrics = evaluate_pair(read_frames(clip), read_frames(out, size), fps)
        tried.append(AtCrop(max_zoom, metrics, seconds, out))
        if abs(metrics.cropping_ratio - last.metrics.cropping_ratio) < CROP_STILL:
            break  # the budget does not bind: ours crops only what its path needs
    return min(tried, key=lambda t: abs(t.metrics.cropping_ratio - crop))


def mirrored(
    out: Path,
    size: tuple[int, int],
    fps: float,
    m,
    sizes: tuple[int, ...] = (REGISTRATION_LONG_SIDE,),
) -> list[float]:
    """The residual shake (px) of ``out`` as it is (``m``), and mirrored left-right,
    upside down and both, at each of the registration's ``sizes``
    (:func:`stabilize.evaluate.shake_spread`)."""
    frames = read_frames(out, size)
    return list(shake_spread(frames, m.residual_shake_px, fps, sizes=sizes).readings)


def span(readings: list[float]) -> str:
    """The readings' mean, and their range."""
    return f"{np.mean(readings):.3f} ({min(readings):.3f}–{max(readings):.3f})"


def zoom_jumps(m) -> tuple[int, float]:
    """How many frames' high-passed zoom (``m.shake_series``) exceeds ``JUMP_PX``, and
    the RMS zoom of the others (px)."""
    zoom = np.asarray(m.shake_series, np.float64).reshape(-1, 4)[:, 3]
    jumps = np.abs(zoom) > JUMP_PX
    rest = float(np.sqrt(np.mean(zoom[~jumps] ** 2))) if (~jumps).any() else 0.0
    return int(jumps.sum()), rest


def _row(clip: str, tool: str, m, seconds: float | None) -> str:
    t = f"{seconds:7.1f}" if seconds is not None else f"{'':7s}"
    parts = " / ".join(f"{x:.2f}" for x in m.shake_components_px)
    jumps, rest = zoom_jumps(m)
    return (
        f"{clip:28s}{tool:10s}{m.residual_shake_px:9.3f}{m.wobble_px:7.3f}{m.stability:7.3f}"
        f"{m.cropping_ratio:7.3f}{m.distortion:7.3f}{t}   {parts}   {jumps} / {rest:.2f}"
    )


if __name__ == "__main__":
    main()
