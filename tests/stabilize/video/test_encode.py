"""The encoder's failures: one line, FFmpeg's own cause, a full disk named."""

from __future__ import annotations

import numpy as np
import pytest

from stabilize.video import FrameWriter
from stabilize.video.containers import container_for
from stabilize.video.encode import EncodeError, encoder_message


def test_a_full_disk_says_so():
    # /dev/full takes every write with ENOSPC: the encoder dies as on a full disk.
    with pytest.raises(EncodeError, match="the disk is full"):
        with FrameWriter("/dev/full", (64, 64), 30.0, container=container_for("x.mp4")) as w:
            for _ in range(200):
                w.write(np.zeros((64, 64, 3), np.uint8))


def test_the_message_is_the_first_line_ffmpeg_gave():
    stderr = "[avi] ADTS is only supported with codec tag 0x1610\n[vf#0:0] Task finished\n"
    assert encoder_message(stderr, 1) == (
        "the encoder failed: [avi] ADTS is only supported with codec tag 0x1610"
    )
    assert encoder_message("", 3) == "the encoder failed: exit status 3"
