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


def test_an_interrupt_while_the_encoder_starts_ends_it(tmp_path, monkeypatch):
    # Ctrl-C or SIGTERM inside Popen (while it waits to hear that the exec worked) raised
    # with FFmpeg started and no handle to it: it wrote its file once the caller had
    # removed it (a SIGTERM test found a .partial.mp4 left, once in five suite runs)
    import signal
    import subprocess

    from stabilize.video import encode

    real, started = subprocess.Popen, []

    def interrupted(*args, **kwargs):
        started.append(real(*args, **kwargs))
        signal.raise_signal(signal.SIGINT)  # its handler runs before this returns
        return started[-1]

    monkeypatch.setattr(encode.subprocess, "Popen", interrupted)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)  # (a worker's may not)
    try:
        with pytest.raises(KeyboardInterrupt):
            FrameWriter(tmp_path / "a.mp4", (64, 64), 30.0, container=container_for("a.mp4"))
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back
        assert started[0].returncode is not None  # killed and reaped, not left going
    finally:
        signal.signal(signal.SIGINT, before)
        started[0].kill()
        started[0].wait()
