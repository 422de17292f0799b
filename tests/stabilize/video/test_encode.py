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


def test_an_interrupt_while_the_encoder_finishes_stops_it(tmp_path, monkeypatch):
    # A batch's worker stopped while FFmpeg wrote the file's end went on to remove its
    # temporary output, and FFmpeg, left running, wrote it again (a stopped batch's test
    # found a .partial file left): the interrupt now ends the encoder before it goes on.
    writer = FrameWriter(tmp_path / "a.mp4", (64, 64), 30.0, container=container_for("a.mp4"))
    process = writer._process
    real_wait, real_kill = process.wait, process.kill
    waits, kills = [], []

    def interrupted(*args, **kwargs):
        waits.append(1)
        if len(waits) == 1:  # the interrupt strikes while close() waits for FFmpeg
            raise KeyboardInterrupt
        return real_wait(*args, **kwargs)

    monkeypatch.setattr(process, "wait", interrupted)
    monkeypatch.setattr(process, "kill", lambda: (kills.append(1), real_kill()))
    with pytest.raises(KeyboardInterrupt):
        with writer:
            writer.write(np.zeros((64, 64, 3), np.uint8))
    assert kills and process.returncode is not None  # killed and reaped, not left going


def test_an_encoder_whose_writer_is_dropped_unclosed_is_ended(tmp_path):
    # An interrupt as `with` starts, before __exit__ is set up, drops the writer with
    # FFmpeg still reading its pipe: it wrote the file once the caller had removed it.
    writer = FrameWriter(tmp_path / "a.mp4", (64, 64), 30.0, container=container_for("a.mp4"))
    process = writer._process
    assert process.poll() is None  # waiting for frames
    del writer
    assert process.returncode is not None  # killed and reaped as the writer went
