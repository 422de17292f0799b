"""What the decoder says of a stream's first frame (FFmpeg's ``showinfo``), where the
stream's header does not say it: the field order of a DV tape's frames, and the HDR10
mastering display and light levels that an HEVC or H.264 stream carries in its frames
(SEI messages), not in its header.

Decoding one frame takes about 30–50 ms here; :func:`stabilize.video.probe.probe` asks
only where the header leaves one of them open.
"""

from __future__ import annotations

from pathlib import Path

from stabilize.video.binary import filter_log


def first_frame_report(path: str | Path, input_args: tuple = ()) -> str:
    """FFmpeg's ``showinfo`` lines for the first frame of the first video stream (its
    flags, its side data), or ``""`` where none decodes."""
    log = filter_log(path, "showinfo", input_args, ("-frames:v", "1"))
    return "\n".join(line for line in log.splitlines() if "Parsed_showinfo" in line)
