"""Cuts in an edited clip: found where two shots meet, nowhere else, and no turn read
across them."""

from __future__ import annotations

import csv
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rotation import so3
from stabilize import Settings, stabilize_video
from stabilize.motion.cuts import LIKENESS, likeness, thumbnail, unrelated_pairs
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
    np.testing.assert_array_equal(unrelated_pairs(alike, support), [False, False, True, False])


def edited(out: Path, *shots: tuple[Path, float]) -> Path:
    """A second of each (clip, start s), joined as an editor joins them."""
    cmd, chains = [ffmpeg_exe(), "-v", "error"], []
    for k, (clip, start) in enumerate(shots):
        cmd += ["-ss", str(start), "-t", "1", "-i", str(clip)]
        chains.append(f"[{k}:v]setpts=PTS-STARTPTS,scale=424:240,setsar=1,fps=30[s{k}]")
    joined = "".join(f"[s{k}]" for k in range(len(shots))) + f"concat=n={len(shots)}:v=1[v]"
    graph = ";".join([*chains, joined])
    cmd += ["-filter_complex", graph, "-map", "[v]", "-c:v", "libx264", "-crf", "16", str(out)]
    subprocess.run(cmd, check=True)
    return out


def test_a_run_of_unlike_pairs_is_a_subject_sweeping_past_not_a_cut():
    # cockatoo's middle third: the bird's head swings past, none of the flow agrees, and
    # three pairs in a row read 36-130 times their neighbours' unlikeness
    calm = [0.999, 0.998, 0.999, 0.997, 0.999, 0.998, 0.999, 0.999]
    sweep = np.array([*calm, 0.721, 0.84, 0.719, *calm])
    assert not unrelated_pairs(sweep, np.zeros(len(sweep))).any()
    once = np.array([*calm, 0.84, *calm])  # the same drop, alone: a cut
    np.testing.assert_array_equal(np.flatnonzero(unrelated_pairs(once, np.zeros(len(once)))), [8])


@pytest.fixture(scope="module")
def two_shots(shared: Path, tmp_path_factory) -> Path:
    """A second of hero7's walk cut to a second of karma's flight."""
    gopro = shared / "data" / "gopro"
    out = tmp_path_factory.mktemp("cut") / "cut.mp4"
    return edited(out, (gopro / "hero7.mp4", 0.0), (gopro / "karma.mp4", 0.0))


def test_a_cut_is_found_and_no_turn_is_read_across_it(two_shots, tmp_path):
    # the vote read a jump there, which the smoothed path spread over a second each side
    summary, path = stabilize_video(two_shots, tmp_path / "out.mp4", Settings(fov=70.0))
    assert (
        "a cut (a change of shot) at 1.00 s: its turn is taken from the frames beside it, "
        "and each shot is planned on its own" in (summary["notices"])
    )
    steps = np.degrees(so3.angle(path.rotations))
    at = int(np.argmin(np.abs(path.times[1:] - 1.0)))
    assert steps[at] <= np.percentile(np.delete(steps, at), 90)  # as its neighbours turn
    # each shot planned as a clip of its own: karma's steady flight keeps its view
    # (zoom 1.011) where hero7's walk needs 1.148, once spent on both
    assert path.zoom[at + 1] < 1.05 < path.zoom[at]
    assert summary["cuts"] == [pytest.approx(1.0)]


def test_the_rotations_file_marks_a_cut(two_shots, tmp_path):
    # its row was a turn like any other's, 1.7 degrees of no camera's motion
    from typer.testing import CliRunner

    from stabilize.cli import app

    out = tmp_path / "rot.csv"
    result = CliRunner().invoke(app, ["rotations", str(two_shots), "-o", str(out), "--fov", "70"])
    assert result.exit_code == 0, result.output
    assert "a cut (a change of shot) at 1.00 s: marked in the rotations' cut column" in (
        result.output
    )
    with open(out) as f:
        marked = [int(row["frame"]) for row in csv.DictReader(f) if row["cut"] == "1"]
    assert marked == [29]  # frames 29 -> 30, at 1.00 s


def test_gyroflow_is_given_no_turn_across_a_cut(two_shots, tmp_path):
    # Gyroflow integrates each rate: the cut's row, 5.6 degrees, would turn karma's shot
    from typer.testing import CliRunner

    from stabilize.cli import app
    from stabilize.gyro.readers import read_gcsv

    out = tmp_path / "visual.gcsv"
    args = ["rotations", str(two_shots), "--gcsv", str(out), "--fov", "70"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "pairs' turns in the .gcsv are taken from the pairs beside them" in result.output
    speed = np.linalg.norm(read_gcsv(out).rates, axis=1)
    assert speed[29] <= np.percentile(np.delete(speed, 29), 90)  # frames 29 -> 30


def test_a_clip_of_one_shot_has_no_cut(tmp_path):
    summary, _ = stabilize_video(SAMPLE / "clip.mp4", tmp_path / "out.mp4", Settings(fov=70.0))
    assert not any("change of shot" in n for n in summary["notices"])
    assert summary["cuts"] == []


def test_a_cut_between_two_shots_of_one_place_is_found(shared, tmp_path):
    # karma's first second cut to its fourth: the pictures look alike (0.906), but 260
    # times less alike than the pairs around them, and 2.3% of the flow agrees
    karma = shared / "data" / "gopro" / "karma.mp4"
    clip = edited(tmp_path / "cut.mp4", (karma, 0.0), (karma, 3.0))
    summary, path = stabilize_video(clip, tmp_path / "out.mp4", Settings(fov=70.0))
    assert any("a cut (a change of shot) at 1.00 s" in n for n in summary["notices"])
    assert path.shots == (0, 30)


@pytest.mark.parametrize(
    "interruption",
    [
        "eq=brightness=-1:enable='eq(n,30)'",  # a black frame: read as two cuts
        "eq=brightness=-1:enable='between(n,30,32)'",  # three
        "eq=brightness=1:enable='eq(n,30)'",  # a white one (a flash that blinds)
    ],
)
def test_a_shot_that_resumes_after_an_interruption_is_not_cut(shared, tmp_path, interruption):
    from stabilize.motion.cuts import track_breaks
    from stabilize.motion.estimate import estimate_rotations
    from stabilize.video import probe

    hero7 = shared / "data" / "gopro" / "hero7.mp4"
    clip = tmp_path / "interrupted.mp4"
    graph = f"scale=424:240,{interruption}"
    cmd = [ffmpeg_exe(), "-v", "error", "-t", "2", "-i", str(hero7), "-vf", graph, "-an"]
    subprocess.run([*cmd, "-c:v", "libx264", "-crf", "16", str(clip)], check=True)
    track = estimate_rotations(clip, probe(clip), Settings(fov=70.0))
    breaks = track_breaks(track)
    assert breaks.unrelated.any() and not breaks.cuts.any()
    summary, path = stabilize_video(clip, tmp_path / "out.mp4", Settings(fov=70.0))
    assert summary["cuts"] == [] and path.shots == (0,)
    assert np.ptp(path.zoom) == 0  # one zoom for the one shot


def test_black_frames_are_one_picture_not_a_cut_each(shared, tmp_path):
    # a second of black (a lens cap, a camera's first frames) read 29 cuts among itself
    black = tmp_path / "black.mp4"
    lavfi = ["-f", "lavfi", "-i", "color=black:s=424x240:d=1:r=30", "-pix_fmt", "yuv420p"]
    subprocess.run([ffmpeg_exe(), "-v", "error", *lavfi, str(black)], check=True)
    hero7 = shared / "data" / "gopro" / "hero7.mp4"
    clip = edited(tmp_path / "opening.mp4", (black, 0.0), (hero7, 0.0))
    summary, _ = stabilize_video(clip, tmp_path / "out.mp4", Settings(fov=70.0))
    assert summary["cuts"] == [pytest.approx(1.0)]  # where the picture begins


def test_a_montage_is_said_in_one_line_naming_its_first_ten_cuts():
    from stabilize.motion.track import VisualTrack
    from stabilize.pipeline import _breaks

    n = 60
    alike = np.full(n, 0.99)
    alike[4::5] = 0.2  # a cut every fifth pair: 12
    track = VisualTrack.from_rotations(np.arange(n + 1) / 30, np.repeat(np.eye(3)[None], n, 0))
    track = replace(track, support=np.full(n, 0.01), likeness=alike)
    said: list[str] = []
    assert _breaks(track, said.append).cuts.sum() == 12
    assert said == [
        "12 cuts (changes of shot) at 0.17 s, 0.33 s, 0.50 s, 0.67 s, 0.83 s, 1.00 s, 1.17 s, "
        "1.33 s, 1.50 s, 1.67 s and 2 more: their turns are taken from the frames beside them, "
        "and each shot is planned on its own"
    ]
