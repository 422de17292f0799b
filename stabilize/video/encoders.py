"""Video encoders: how each takes the job's quality and speed (``--crf``, ``--preset``).

x264 and x265 take both as they are. The others get their own scales: VP9 constant
quality needs ``-b:v 0``, and its speed is ``-cpu-used``; SVT-AV1 numbers its presets;
an image sequence's JPEG takes a quantiser, and its PNG or TIFF neither (lossless); a GIF
takes none (its palette is its quality), nor do the editing codecs, ProRes and DNxHR
(a profile each, :data:`PROFILES`).
An encoder not listed gets ``-crf`` and ``-preset`` as they are, and the pre-flight check
(:func:`stabilize.video.preflight.check_encoder`) refuses what it does not take.
"""

from __future__ import annotations

from collections.abc import Callable

# x264's preset names, slowest last, as a 0..1 scale for the encoders that number theirs.
X264_PRESETS = (
    "ultrafast", "superfast", "veryfast", "faster", "fast",
    "medium", "slow", "slower", "veryslow", "placebo",
)  # fmt: skip
DEFAULT_PRESET = "medium"
# The quality a user gets from the default --crf 18 of x264, per encoder's own scale.
DEFAULT_CRF = {"libx264": 18, "libx265": 20, "libvpx-vp9": 31, "libsvtav1": 30, "libaom-av1": 30}
# The encoders whose frames lean on one another: no picture file holds one alone
VIDEO_ONLY = frozenset({"libx264", "libx265", "libvpx-vp9", "libsvtav1", "libaom-av1"})
# JPEG's and MPEG-2's quantiser (-q:v, 1 best to 31) per step of x264's CRF: 18 gives 2,
# the usual choice for frames kept for analysis, and a DVD's best
CRF_PER_JPEG_Q = 9
# Theora's quality (-q:v, 0 to 10, best last) falls by one per this many steps of CRF
CRF_PER_THEORA_Q = 9
# Encoders whose time base must be a frame rate their standard lists: a 90 kHz clock
# (a delayed video's, :func:`stabilize.video.encode.output_args`) does not open them
FRAME_CLOCKED = frozenset({"mpeg1video", "mpeg2video"})


def _speed(preset: str, slowest: int, fastest: int) -> int:
    """An x264 preset name on an encoder's numbered speed scale (x264's medium → middle)."""
    if preset.isdigit():
        return int(preset)
    rank = X264_PRESETS.index(preset) / (len(X264_PRESETS) - 1) if preset in X264_PRESETS else 0.5
    return round(fastest + rank * (slowest - fastest))


def _x26x(crf: int, preset: str) -> list[str]:
    return ["-crf", str(crf), "-preset", preset]


def _vp9(crf: int, preset: str) -> list[str]:
    return ["-crf", str(crf), "-b:v", "0", "-deadline", "good", "-row-mt", "1",
            "-cpu-used", str(_speed(preset, 0, 5))]  # fmt: skip


def _svtav1(crf: int, preset: str) -> list[str]:
    return ["-crf", str(crf), "-preset", str(_speed(preset, 2, 12))]


def _aom(crf: int, preset: str) -> list[str]:
    return ["-crf", str(crf), "-cpu-used", str(_speed(preset, 1, 8)), "-row-mt", "1"]


def _jpeg(crf: int, preset: str) -> list[str]:
    return ["-q:v", str(min(max(round(crf / CRF_PER_JPEG_Q), 1), 31))]


def _theora(crf: int, preset: str) -> list[str]:
    # a quality of 0 to 10, best last. x264's CRF 18 gives 8: on a rendered 4 s 320x180
    # clip 38.5 dB PSNR at 2.6x the size of x264's 41.0 dB; Theora's best, 10 (CRF 0),
    # reads 40.7 dB at 4x
    return ["-q:v", str(min(max(round(10 - crf / CRF_PER_THEORA_Q), 0), 10))]


def _lossless(crf: int, preset: str) -> list[str]:
    return []  # PNG and TIFF keep every sample: no quality to choose


def _gif(crf: int, preset: str) -> list[str]:
    return []  # its palette is its quality (the container's filter): no scale to set


# The registry: an encoder's name → its arguments for (crf, preset).
ENCODERS: dict[str, Callable[[int, str], list[str]]] = {
    "libx264": _x26x,
    "libx265": _x26x,
    "libvpx-vp9": _vp9,
    "libsvtav1": _svtav1,
    "libaom-av1": _aom,
    "mjpeg": _jpeg,
    "mpeg2video": _jpeg,  # a quantiser, as JPEG's: MPEG-2 has no constant quality
    "mpeg1video": _jpeg,
    "libtheora": _theora,
    "png": _lossless,
    "tiff": _lossless,
    "gif": _gif,
}


# Editing codecs: no quality scale, a profile by the frames' depth (8 bits; 10 or more).
# DNxHD's own profile took only broadcast sizes and bit rates ("video parameters
# incompatible with DNxHD"); DNxHR takes any size, HQX alone at 10 bits. ProRes 422 HQ
# (profile 3, both encoders), where prores_aw's default was Standard.
PROFILES: dict[str, tuple[list[str], list[str]]] = {
    "dnxhd": (["-profile:v", "dnxhr_hq"], ["-profile:v", "dnxhr_hqx"]),
    "prores_ks": (["-profile:v", "3"], ["-profile:v", "3"]),
    "prores_aw": (["-profile:v", "3"], ["-profile:v", "3"]),
}


# Their profiles for colour at full resolution (4:4:4, asked for with --pix-fmt): ProRes
# 4444 and DNxHR 444. The 422 profiles took 4:4:4 pixels silently, ProRes writing a 422
# HQ file of them (apch), DNxHR refusing ("pixel format is incompatible")
FULL_CHROMA_PROFILES: dict[str, list[str]] = {
    "dnxhd": ["-profile:v", "dnxhr_444"],
    "prores_ks": ["-profile:v", "4"],
    "prores_aw": ["-profile:v", "4"],
}


# The editing codecs' own pixels (4:2:2, as their profiles above store it) at either
# depth. Given the pipe's 4:2:0, FFmpeg converted to these anyway, after the pipe had
# halved the colour of a 4:2:2 source; named, they let that colour travel whole
# (:func:`stabilize.warp.render.piped_format`)
EDITING_PIX_FMT: dict[str, tuple[str, str]] = {
    "dnxhd": ("yuv422p", "yuv422p10le"),
    "prores_ks": ("yuv422p10le", "yuv422p10le"),
    "prores_aw": ("yuv422p10le", "yuv422p10le"),
}
# ... and for a 4:4:4 or RGB source (a ProRes 4444 master, RGB pictures), their 4:4:4
# (ProRes 4444, DNxHR 444, FULL_CHROMA_PROFILES: 10 bits at either depth), so an
# editor's full colour comes back whole without --pix-fmt (it was written 4:2:2)
EDITING_FULL_PIX_FMT = "yuv444p10le"


def encoder_args(
    codec: str, crf: int | None, preset: str, deep: bool = False, full_chroma: bool = False
) -> list[str]:
    """FFmpeg's arguments for ``codec`` at quality ``crf`` (None: the codec's default),
    for frames of 10 bits or more where ``deep``, of 4:4:4 colour where ``full_chroma``.

    >>> encoder_args("dnxhd", 18, "medium", deep=True)
    ['-c:v', 'dnxhd', '-profile:v', 'dnxhr_hqx']
    >>> encoder_args("prores_ks", 18, "medium", deep=True, full_chroma=True)
    ['-c:v', 'prores_ks', '-profile:v', '4']
    """
    if codec in PROFILES:
        profile = FULL_CHROMA_PROFILES[codec] if full_chroma else PROFILES[codec][deep]
        return ["-c:v", codec, *profile]
    quality = DEFAULT_CRF.get(codec, 18) if crf is None else crf
    return ["-c:v", codec, *ENCODERS.get(codec, _x26x)(quality, preset)]


def unused_options(codec: str, crf: int | None, preset: str = DEFAULT_PRESET) -> tuple[str, ...]:
    """Notices where ``--crf`` or ``--preset`` was given for an encoder with no use for
    it: PNG and TIFF keep every sample, a GIF's palette is its quality, ProRes's and
    DNxHR's profile is; JPEG, MPEG-2 and Theora have no speed to choose (each was ignored
    silently). A preset left at its default is not said to be unused."""
    make = ENCODERS.get(codec, _x26x)
    said = []
    if crf is not None and (codec in PROFILES or make(0, "medium") == make(63, "medium")):
        why = "it keeps every sample" if make is _lossless else "its palette is its quality"
        why = "its profile is its quality" if codec in PROFILES else why
        said.append(f"--crf {crf} has no effect on {codec}: {why}")
    quality = DEFAULT_CRF.get(codec, 18)
    ignores = codec in PROFILES or make(quality, X264_PRESETS[0]) == make(quality, X264_PRESETS[-1])
    if preset != DEFAULT_PRESET and ignores:
        said.append(f"--preset {preset} has no effect on {codec}: it has no speed to choose")
    return tuple(said)
