"""Variable frame rate: detecting it, and restamping an encoded clip with the source's own
frame times."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from stabilize.video.binary import local
from stabilize.video.containers import FILE_TYPE_KEYS

TIMESCALE = 90_000  # ticks per second of retimed video (MPEG's clock)


CLOCK_SLACK = 1e-3  # s: a millisecond clock (MKV, WebM) rounds each time by up to 0.5 ms


def is_variable_rate(times: NDArray, tolerance: float = 0.01) -> bool:
    """Whether the frames depart from a constant rate: some time lies off the straight
    line from the first to the last by more than ``tolerance`` of a frame interval, and
    by more than a millisecond clock's rounding (``CLOCK_SLACK``)."""
    times = np.asarray(times, dtype=np.float64)
    if len(times) < 3:
        return False
    step = (times[-1] - times[0]) / (len(times) - 1)
    line = times[0] + step * np.arange(len(times))
    return bool(np.max(np.abs(times - line)) > max(tolerance * step, CLOCK_SLACK))


def thinned(times: NDArray, interval: float) -> NDArray[np.intp]:
    """The frames kept where none may follow the last kept sooner than ``interval`` s:
    each the first that comes late enough (every other frame of a 60 fps clip, at 20 ms).

    >>> thinned(np.arange(7) / 60, 0.02).tolist()
    [0, 2, 4, 6]
    >>> thinned(np.array([0.0, 0.0467, 0.0933, 0.1, 0.1467]), 0.02).tolist()
    [0, 1, 2, 4]
    """
    times = np.asarray(times, dtype=np.float64)
    kept = [0] if len(times) else []
    for k in range(1, len(times)):
        if times[k] - times[kept[-1]] >= interval - 1e-6:  # (a clock's rounding)
            kept.append(k)
    return np.array(kept, dtype=np.intp)


def retime(
    src: str | Path,
    dst: str | Path,
    times: NDArray,
    muxer: str = "",
    start: float = 0.0,
    options: tuple[str, ...] = (),
) -> None:
    """Copy ``src`` (written at a constant rate, without B-frames) to ``dst`` with the
    video frames stamped at ``times`` (s, one per frame); other streams are copied as they
    are. No re-encoding: the packets are remuxed with new timestamps.

    The first frame is stamped at ``start`` (s), where the source's video began after
    its first stream. ``muxer`` names the output's format (empty: from its suffix), and
    ``options`` are its options as FFmpeg's command line takes them (``-movflags
    +faststart+use_metadata_tags``: without them a phone's own tags, its location among
    them, were lost from a variable-rate clip, and the index was written last). The
    file's metadata and chapters come along.

    FFmpeg's command line cannot take per-frame timestamps for frames arriving through a
    pipe, so this step uses PyAV (FFmpeg's libraries) to rewrite them.
    """
    import av

    times = np.asarray(times, dtype=np.float64) - float(times[0]) + start
    ticks = np.round(times * TIMESCALE).astype(np.int64)
    step = np.arange(len(ticks))
    ticks = np.maximum.accumulate(ticks - step) + step  # strictly rising, as a muxer needs
    last = np.median(np.diff(ticks)) if len(ticks) > 1 else TIMESCALE // 30
    gaps = np.diff(ticks, append=ticks[-1] + last)
    named = {k.lstrip("-"): v for k, v in zip(options[::2], options[1::2], strict=True)}
    written = av.open(local(dst), "w", format=muxer or None, container_options=named)
    with av.open(local(src)) as inp, written as out:
        video = inp.streams.video[0]
        # the tracks the muxer writes again, from the video's timecode tag and from the
        # chapter list: copied too, each failed the remux once the work was done
        # ("Invalid argument", "Invalid data found when processing input")
        chaptered = bool(inp.chapters())
        kept = [s for s in inp.streams if not _rewritten(s, video, chaptered)]
        streams = {s.index: out.add_stream_from_template(s) for s in kept}
        out.metadata.update({k: v for k, v in inp.metadata.items() if k not in FILE_TYPE_KEYS})
        for s in kept:
            streams[s.index].metadata.update(s.metadata)
            streams[s.index].disposition = s.disposition  # which track plays by default
            # the tag the same muxer chose (HEVC's hvc1, which Apple's players need, where
            # this remux wrote hev1, which they do not play)
            if s.type in ("video", "audio"):  # (a data stream has none to set)
                streams[s.index].codec_tag = s.codec_tag
        if inp.chapters():
            out.set_chapters(inp.chapters())
        streams[video.index].time_base = Fraction(1, TIMESCALE)
        k = 0  # without B-frames, packets come in display order: the k-th is frame k
        for packet in inp.demux():
            if packet.dts is None or packet.stream.index not in streams:  # a flush packet
                continue
            if packet.stream is video:
                if k >= len(ticks):
                    raise RuntimeError(f"{src}: more frames than the {len(ticks)} timestamps")
                packet.time_base = Fraction(1, TIMESCALE)
                packet.pts = packet.dts = int(ticks[k])
                packet.duration = int(gaps[k])
                k += 1
            packet.stream = streams[packet.stream.index]
            out.mux(packet)


AVDISCARD_ALL = 48  # FFmpeg's mark on a track it reads nothing from: MP4's chapter track


def _rewritten(stream, video, chaptered: bool) -> bool:
    """Whether ``stream`` is a track the muxer writes again: a timecode track (QuickTime's
    tmcd, a data track with a timecode) from the ``video``'s own timecode tag, or MP4's
    chapter track (read as a data track FFmpeg takes nothing from) from the chapters."""
    if stream.type != "data":
        return False
    timecode = "timecode" in stream.metadata and "timecode" in video.metadata
    return timecode or (chaptered and stream.discard == AVDISCARD_ALL)
