"""A clip with a display rotation, decoded as its sensor stored it and turned to be shown."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.video import ffmpeg_exe, i420, probe, read_frames
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


# FFmpeg's display-matrix options → (quarter turns, mirror) from stored to shown. Its
# listing reads a flip as a rotation of its own: a mirror alone as "-180 degrees"
FLIPPED = {
    "-display_hflip": (0, True),
    "-display_vflip": (2, True),
    "-display_rotation 90 -display_hflip": (3, True),
    "-display_rotation 90 -display_vflip": (1, True),
}


def flipped(folder, options: str):
    out = folder / "flipped.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", *options.split(), "-i", str(SAMPLE / "clip.mp4")]
    subprocess.run([*cmd, "-c", "copy", "-t", "0.5", str(out)], check=True)
    return out


@pytest.mark.parametrize(("options", "transform"), list(FLIPPED.items()))
def test_a_flip_in_the_display_matrix_is_read_and_undone_as_shown(tmp_path, options, transform):
    clip = flipped(tmp_path, options)
    info = probe(clip)
    assert (info.rotation // 90, info.mirror) == transform
    raw = info.stored()
    stored = next(iter(read_frames(clip, info=raw)))
    shown = next(iter(read_frames(clip, info=info)))  # FFmpeg's own turn and flip
    np.testing.assert_array_equal(turn(stored, raw.turns, mirror=raw.mirrored), shown)


def test_a_front_cameras_portrait_clip_comes_out_as_players_show_it(tmp_path):
    # turned upside down (a mirror read as "-180 degrees"), or mirrored, before. The
    # stored frames are the level clip's, so its stabilised frames, turned and mirrored
    # as the matrix says, are what must come out
    outs = []
    for options in ("", "-display_rotation 90 -display_hflip"):
        folder = tmp_path / str(len(outs))
        folder.mkdir()
        outs.append(folder / "out.mp4")
        summary, _ = stabilize_video(flipped(folder, options), outs[-1], Settings(fov=70.0))
    assert summary["display_mirror"]
    level, written = (next(iter(read_frames(out))).astype(int) for out in outs)
    shown = np.rot90(level[:, ::-1], 3)
    assert written.shape == shown.shape
    assert np.abs(written - shown).mean() < 3  # the encoder's (2.1)
    # the listed turn alone, the other turn, the other flip: 34, 24, 35
    for wrong in (np.rot90(level, 1), np.rot90(level, 3), np.rot90(level[::-1], 3)):
        assert np.abs(written - wrong).mean() > 10


def test_a_clip_that_fades_in_from_black_tells_its_flip_by_a_later_frame(tmp_path):
    # its first frame, one colour, fits every turn and flip alike
    faded = tmp_path / "faded.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(SAMPLE / "clip.mp4"), "-t", "1.5", "-an"]
    subprocess.run(
        [*cmd, "-vf", "fade=in:st=0:d=0.5", "-preset", "ultrafast", str(faded)], check=True
    )
    clip = tmp_path / "flipped.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-display_rotation", "90", "-display_hflip"]
    subprocess.run([*cmd, "-i", str(faded), "-c", "copy", str(clip)], check=True)
    info = probe(clip)
    assert (info.rotation, info.mirror) == (270, True)


def test_a_frame_that_cannot_tell_a_flip_keeps_the_listed_rotation(tmp_path):
    black = tmp_path / "black.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-f", "lavfi", "-i", "color=black:s=64x48:d=0.2"]
    subprocess.run([*cmd, str(tmp_path / "b.mp4")], check=True)
    cmd = [ffmpeg_exe(), "-v", "error", "-display_rotation", "90", "-i", str(tmp_path / "b.mp4")]
    subprocess.run([*cmd, "-c", "copy", str(black)], check=True)
    info = probe(black)
    assert (info.rotation, info.mirror, info.size) == (90, False, (64, 48))
