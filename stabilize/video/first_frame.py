"""What the decoder says of a stream's first frame (FFmpeg's ``showinfo``), where the
stream's header does not say it: the field order of a DV tape's frames, and the HDR10
mastering display and light levels that an HEVC or H.264 stream carries in its frames
(SEI messages), not in its header.

Decoding one frame takes about 30–50 ms here; :func:`stabilize.video.probe.probe` asks
only where the header leaves one of them open.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from stabilize.video.binary import ffmpeg_exe


def first_frame_report(path: str | Path, input_args: tuple = ()) -> str:
    """FFmpeg's ``showinfo`` lines for the first frame of the first video stream (its
    flags, its side data), or ``""`` where none decodes."""
    cmd = [ffmpeg_exe(), "-hide_banner", "-nostdin", *input_args, "-i", str(path)]
    cmd += ["-map", "0:v:0", "-vf", "showinfo", "-frames:v", "1", "-f", "null", "-"]
    result = subprocess.run(cmd, capture_output=True, text=True, errors="replace")
    return "\n".join(line for line in result.stderr.splitlines() if "Parsed_showinfo" in line)
