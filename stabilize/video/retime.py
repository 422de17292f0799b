"""Variable frame rate: detecting it, and restamping an encoded clip with the source's own
frame times."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

TIMESCALE = 90_000  # ticks per second of retimed video (MPEG's clock)


def is_variable_rate(times: NDArray, tolerance: float = 0.01) -> bool:
    """Whether frame intervals differ from their median by more than ``tolerance`` of it."""
    steps = np.diff(np.asarray(times, dtype=np.float64))
    if steps.size < 2:
        return False
    median = float(np.median(steps))
    return bool(np.max(np.abs(steps - median)) > tolerance * median)


def retime(src: str | Path, dst: str | Path, times: NDArray) -> None:
    """Copy ``src`` (written at a constant rate, without B-frames) to ``dst`` with the
    video frames stamped at ``times`` (s, one per frame); other streams are copied as they
    are. No re-encoding: the packets are remuxed with new timestamps.

    FFmpeg's command line cannot take per-frame timestamps for frames arriving through a
    pipe, so this step uses PyAV (FFmpeg's libraries) to rewrite them.
    """
    import av

    times = np.asarray(times, dtype=np.float64) - float(times[0])
    ticks = np.round(times * TIMESCALE).astype(np.int64)
    step = np.arange(len(ticks))
    ticks = np.maximum.accumulate(ticks - step) + step  # strictly rising, as a muxer needs
    last = np.median(np.diff(ticks)) if len(ticks) > 1 else TIMESCALE // 30
    gaps = np.diff(ticks, append=ticks[-1] + last)
    with av.open(str(src)) as inp, av.open(str(dst), "w", format="mp4") as out:
        video = inp.streams.video[0]
        streams = {s.index: out.add_stream_from_template(s) for s in inp.streams}
        streams[video.index].time_base = Fraction(1, TIMESCALE)
        k = 0  # without B-frames, packets come in display order: the k-th is frame k
        for packet in inp.demux():
            if packet.dts is None:  # a demuxer's flush packet
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
