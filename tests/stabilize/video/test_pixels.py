"""Anamorphic video: a stream whose pixels are not square is decoded widened to square
pixels, at the size a player shows it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stabilize.video import probe, read_frames
from tests.stabilize.helpers import SAMPLE, held_upright, squeezed


@pytest.fixture(scope="module")
def anamorphic(tmp_path_factory) -> Path:
    return squeezed(tmp_path_factory.mktemp("anamorphic"))


def test_an_anamorphic_stream_decodes_widened_to_square_pixels(anamorphic):
    info = probe(anamorphic)
    assert info.pixel_aspect == "4:3" and info.coded == (360, 480) and info.size == (360, 640)
    widened = np.stack(list(read_frames(anamorphic, info=info)))
    square = np.stack(list(read_frames(SAMPLE / "clip.mp4")))
    assert widened.shape == square.shape  # every frame, at the size it is shown
    # the picture as shown: within the squeeze's and the encode's loss of the original
    # (3.1 grey levels here)
    assert np.abs(widened.astype(float) - square).mean() < 5
    planar = next(iter(read_frames(anamorphic, info=info, pix_fmt="yuv420p")))
    assert planar.shape == (540, 640)


def test_a_square_stream_is_decoded_as_it_is():
    info = probe(SAMPLE / "clip.mp4")
    assert info.pixel_aspect == "1:1" and info.coded is None
    assert info.decoded_size == info.size


def test_an_anamorphic_stream_held_upright_widens_its_stored_width(anamorphic, tmp_path):
    info = probe(held_upright(anamorphic, tmp_path))
    assert info.size == (640, 360) and info.coded == (480, 360)  # shown upright
    raw = info.stored()  # as the sensor stored it: 4:3 pixels along its rows
    assert raw.size == (360, 640) and raw.coded == (360, 480)
    assert next(iter(read_frames(raw.path, info=raw))).shape == (360, 640, 3)
    assert next(iter(read_frames(info.path, info=info))).shape == (640, 360, 3)
