"""Cuts in an edited clip: found where two shots meet, nowhere else, and no turn read
across them."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from rotation import so3
from stabilize import Settings, stabilize_video
from stabilize.motion.cuts import LIKENESS, cut_pairs, likeness, thumbnail
from stabilize.video import ffmpeg_exe, read_frames
from tests.stabilize.helpers import SAMPLE


def test_a_turned_or_brightened_picture_looks_alike_and_another_does_not():
    frames = list(read_frames(SAMPLE / "clip.mp4"))
    first = thumbnail(frames[0])
    assert likeness(first, thumbnail(np.roll(frames[0], 40, axis=1))) > 0.95  # turned
    brighter = np.clip(frames[0] * 1.4 + 20, 0, 255).astype(np.uint8)  # an exposure jump
    assert likeness(first, thumbnail(brighter)) > 0.95
    flipped = frames[0][::-1, ::-1].copy()  # another picture of the same colours
    assert likeness(first, thumbnail(flipped)) < LIKENESS


def test_a_cut_needs_both_an_unlike_picture_and_no_agreement():
    alike, support = np.array([0.9, 0.3, 0.3, 0.9]), np.array([0.01, 0.2, 0.01, 0.2])
    np.testing.assert_array_equal(cut_pairs(alike, support), [False, False, True, False])


@pytest.fixture(scope="module")
def two_shots(shared: Path, tmp_path_factory) -> Path:
    """A second of hero7's walk cut to a second of karma's flight, as an editor joins
    them."""
    out = tmp_path_factory.mktemp("cut") / "cut.mp4"
    shot = "trim=0:1,setpts=PTS-STARTPTS,scale=424:240,setsar=1,fps=30"
    graph = f"[0:v]{shot}[a];[1:v]{shot}[b];[a][b]concat=n=2:v=1[v]"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shared / "data" / "gopro" / "hero7.mp4")]
    cmd += ["-i", str(shared / "data" / "gopro" / "karma.mp4"), "-filter_complex", graph]
    subprocess.run([*cmd, "-map", "[v]", "-c:v", "libx264", "-crf", "16", str(out)], check=True)
    return out


def test_a_cut_is_found_and_no_turn_is_read_across_it(two_shots, tmp_path):
    # the vote read a jump there, which the smoothed path spread over a second each side
    summary, path = stabilize_video(two_shots, tmp_path / "out.mp4", Settings(fov=70.0))
    assert (
        "a cut (a change of shot) at 1.00 s: its turn is taken from the frames beside it"
        in (summary["notices"])
    )
    steps = np.degrees(so3.angle(path.rotations))
    at = int(np.argmin(np.abs(path.times[1:] - 1.0)))
    assert steps[at] <= np.percentile(np.delete(steps, at), 90)  # as its neighbours turn
    # each shot planned as a clip of its own: karma's steady flight keeps its view
    # (zoom 1.011) where hero7's walk needs 1.148, once spent on both
    assert path.zoom[at + 1] < 1.05 < path.zoom[at]


def test_a_clip_of_one_shot_has_no_cut(tmp_path):
    summary, _ = stabilize_video(SAMPLE / "clip.mp4", tmp_path / "out.mp4", Settings(fov=70.0))
    assert not any("change of shot" in n for n in summary["notices"])
