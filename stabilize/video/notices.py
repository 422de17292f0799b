"""What of the source's picture the output cannot keep as it was, said before any work.

Each function returns a tuple of notices (empty where nothing is lost), so the job can
add them up: the encoder chosen for a deep source, what cannot travel through the pipe to
the encoder (Dolby Vision's and HDR10+'s metadata, closed captions, alpha), colour and
depth the encoder does not write, fields woven into frames, anamorphic pixels, and black
bars kept still around the picture.
"""

from __future__ import annotations

from stabilize.video.colour import DOLBY_BASE
from stabilize.video.encode import Encoding
from stabilize.video.i420 import chroma, finer, is_deep
from stabilize.video.probe import VideoInfo


def encoder_notice(encoding: Encoding, default: str) -> tuple[str, ...]:
    """A notice where a deep source's output is encoded by another encoder than the
    container's default (HEVC, not H.264: :meth:`Encoding.for_frames`)."""
    if encoding.codec == default:
        return ()
    return (
        f"10-bit video: encoded with {encoding.codec}, which phones and most browsers play "
        f"at 10 bits, where {default} at 10 bits plays in few players (--codec {default} "
        "keeps it)",
    )


def pipe_notices(info: VideoInfo, encoding: Encoding, asked: bool = False) -> tuple[str, ...]:
    """Notices for what of the source's picture does not reach the output: what cannot
    travel through the pipe to the encoder (Dolby Vision's and HDR10+'s metadata, closed
    captions, alpha), or what the ``encoding`` does not write (colour as fine, depth:
    where its pixel format was ``asked`` for, --pix-fmt is named as the cause; HDR10's
    static metadata)."""
    notices = dolby_vision_notice(info.colour.dolby_vision)
    if info.colour.hdr10_plus:
        notices += (
            "HDR10+ (its tone mapping for each frame, SMPTE 2094-40) left out: it does not "
            "travel through the pipe; the HDR10 picture and its static metadata are kept, "
            "and play as HDR10",
        )
    if info.captions:
        notices += (
            "closed captions (EIA-608/708, carried in the video's frames) left out: they "
            "do not travel through the pipe to the encoder",
        )
    if info.alpha:
        notices += (
            f"the source's alpha (transparency, {info.pix_fmt}) is left out: the frames "
            "are stabilised and written without it",
        )
    notices += chroma_notice(info.pix_fmt, encoding, asked)
    if is_deep(info.pix_fmt) and not is_deep(encoding.pix_fmt):
        why = (
            "as --pix-fmt asks" if asked else f"{encoding.codec} ({encoding.pix_fmt}) holds no more"
        )
        notices += (f"{info.pix_fmt} video written at 8 bits: {why}",)
    if info.colour.hdr10_lost(encoding.codec):
        notices += (
            f"HDR10's mastering display and light levels left out: {encoding.codec} does "
            "not write them (libx264 and libx265 do)",
        )
    return notices


def chroma_notice(source: str, encoding: Encoding, asked: bool = False) -> tuple[str, ...]:
    """A notice where the source's colour is finer than the ``encoding`` writes it: a
    camera's or ProRes's 4:2:2, 4:4:4 or RGB pictures written as 4:2:0, which every
    player plays, unless a pixel format is ``asked`` for. (It travels whole to an encoder
    that keeps it: :func:`stabilize.warp.render.piped_format`.)"""
    written = encoding.pix_fmt
    if not finer(source, written):
        return ()
    why = (
        "as --pix-fmt asks"
        if asked
        else f"as {encoding.codec} writes it here; ProRes, DNxHR (--codec prores_ks, dnxhd), "
        "PNG, TIFF and --pix-fmt keep finer colour"
    )
    said = f"the source's {chroma(source)} colour ({source}) is written as {chroma(written)}"
    return (f"{said} ({written}), {why}",)


def dolby_vision_notice(profile: str | None) -> tuple[str, ...]:
    """A notice where a Dolby Vision stream's metadata is left out, naming what its
    picture is without it (:data:`stabilize.video.colour.DOLBY_BASE`)."""
    if profile is None:
        return ()
    base = DOLBY_BASE.get(profile.split(".")[1])
    kept = (
        f"its {base} picture is kept, and plays as that"
        if base
        else "its picture is in Dolby's own colours, which look wrong without it"
    )
    return (f"Dolby Vision (profile {profile}) left out, its metadata does not travel: {kept}",)


def fields_notice(info: VideoInfo) -> tuple[str, ...]:
    """A notice where the frames are deinterlaced (each field into a frame of its own,
    with ``--deinterlace fields``), or where an interlaced stream is not (``--deinterlace
    off``: the warp then blends its fields into combs)."""
    order = {"tff": "top field first", "bff": "bottom field first"}.get(info.field_order)
    if info.fields:
        what = f"interlaced ({order})" if order else "flagged progressive"
        return (
            f"{what}: each field deinterlaced into a frame of its own (FFmpeg's bwdif), "
            f"{info.fps / 2:g} → {info.fps:g} frames a second; the output is progressive",
        )
    if info.deinterlace:
        what = f"interlaced ({order})" if order else "flagged progressive"
        return (f"{what}: each frame deinterlaced (FFmpeg's bwdif); the output is progressive",)
    if order:
        return (f"interlaced ({order}), left so (--deinterlace off): the warp blends its fields",)
    return ()


def pixels_notice(info: VideoInfo) -> tuple[str, ...]:
    """A notice where an anamorphic stream's pixels are not square: it is worked on, and
    written, in square pixels at the size it is shown at."""
    if info.coded is None:
        return ()
    h, w = info.shown_framed_size
    return (
        f"anamorphic (pixels {info.pixel_aspect}): worked on and written in square pixels, "
        f"{w}x{h}, as it is shown",
    )


def bars_notice(info: VideoInfo) -> tuple[str, ...]:
    """A notice where black bars frame the picture: it is stabilised inside them, and
    they stay still."""
    if info.bars is None:
        return ()
    top, bottom, left, right = info.bars
    where = [
        f"{a} and {b} px {side}"
        for a, b, side in ((top, bottom, "above and below"), (left, right, "left and right"))
        if a or b
    ]
    return (
        f"black bars ({'; '.join(where)}): the picture inside them is stabilised, and "
        "they are kept still around it (--bars off: stabilised with it)",
    )
