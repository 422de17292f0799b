"""A clip with a display rotation, decoded as its sensor stored it and turned to be shown."""

from __future__ import annotations

import numpy as np
import pytest

from stabilize.video import i420, probe, read_frames
from stabilize.video.turn import turn
from tests.stabilize.helpers import SAMPLE, held_upright


@pytest.mark.parametrize("rotation", [90, 180, 270])
def test_a_turned_clip_decodes_as_stored_and_turns_as_shown(tmp_path, rotation):
    stored = next(iter(read_frames(SAMPLE / "clip.mp4")))
    tagged = held_upright(SAMPLE / "clip.mp4", tmp_path, rotation)
    info = probe(tagged)
    shown = next(iter(read_frames(tagged, info=info)))
    raw = info.stored()
    assert raw.size == stored.shape[:2] and raw.shown_size == info.size == shown.shape[:2]
    np.testing.assert_array_equal(next(iter(read_frames(tagged, info=raw))), stored)
    np.testing.assert_array_equal(shown, np.rot90(stored, rotation // 90))
    np.testing.assert_array_equal(turn(stored, raw.turns), shown)


def test_a_level_clip_is_its_own_stored_form():
    info = probe(SAMPLE / "clip.mp4")
    assert info.stored() is info and info.turns == 0 and info.shown_size == info.size


@pytest.mark.parametrize("turns", [1, 2, 3])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_an_i420_frame_turns_plane_by_plane(turns, dtype):
    rng = np.random.default_rng(turns)
    planes = [rng.integers(0, 1000, shape).astype(dtype) for shape in ((6, 10), (3, 5), (3, 5))]
    turned = i420.split(turn(i420.join(*planes), turns, planar=True))
    for got, plane in zip(turned, planes, strict=True):
        np.testing.assert_array_equal(got, np.rot90(plane, turns))
