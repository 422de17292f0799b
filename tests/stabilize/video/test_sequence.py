"""Image sequences: read from their lowest number, written as pictures numbered as the
input's (else from 1), at 16 bits a channel for a deep source where the format holds it."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.video import VideoError, ffmpeg_exe, probe, read_frames
from stabilize.video.sequence import first_number, sequence_args, sequence_files


def test_a_sequence_is_found_from_its_lowest_number(tmp_path):
    for n in (99, 100, 250):
        (tmp_path / f"img-{n:05d}.jpg").write_bytes(b"")
    (tmp_path / "img-00007.png").write_bytes(b"")  # another suffix: not of it
    pattern = tmp_path / "img-%05d.jpg"
    assert sorted(sequence_files(pattern)) == [99, 100, 250] and first_number(pattern) == 99
    assert sequence_args(pattern, fps=24) == (
        "-f", "image2", "-start_number", "99", "-framerate", "24",
    )  # fmt: skip
    assert sequence_args(tmp_path / "clip.mp4") == ()


def test_a_video_becomes_pictures_numbered_from_1(shaky, tmp_path):
    pattern = tmp_path / "frames" / "f%04d.png"
    summary, _ = stabilize_video(shaky, pattern, Settings(fov=70.0))
    assert sorted(sequence_files(pattern)) == list(range(1, 61)) and summary["frames"] == 60
    assert any("left out audio" in n for n in summary["notices"])
    assert any("keeps no frame times" in n for n in summary["notices"])
    assert not [p for p in pattern.parent.iterdir() if p.name.startswith(".")]
    video = list(read_frames(shaky))
    pictures = list(read_frames(pattern))
    assert len(pictures) == 60 and pictures[0].shape == video[0].shape
    # stabilised, not black: the pictures' tones are the clip's
    assert abs(np.mean(pictures[30]) - np.mean(video[30])) < 8


def test_pictures_keep_the_input_sequences_numbers_and_a_deep_sources_depth(shaky, tmp_path):
    source = tmp_path / "in" / "RE_frame-%d.png"
    source.parent.mkdir()
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "20"]
    cmd += ["-pix_fmt", "rgb48be", "-start_number", "99", str(source)]
    subprocess.run(cmd, check=True)
    out = tmp_path / "out" / "RE_frame-%d.png"
    summary, _ = stabilize_video(source, out, Settings(fov=70.0))
    assert sorted(sequence_files(out)) == list(range(99, 119))
    assert probe(out).pix_fmt == "rgb48be"  # 10 bits kept, in 16-bit PNG
    assert not any("frame times" in n for n in summary["notices"])  # none to keep


@pytest.mark.parametrize(("name", "codec"), [("%03d.jpg", "mjpeg"), ("%03d.tif", "tiff")])
def test_jpeg_and_tiff_pictures(shaky, tmp_path, name, codec):
    clip = tmp_path / "short.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-t", "0.5", "-c:v", "libx264"]
    subprocess.run([*cmd, str(clip)], check=True)
    summary, _ = stabilize_video(clip, tmp_path / name, Settings(fov=70.0))
    assert len(sequence_files(tmp_path / name)) == summary["frames"] == 15
    assert probe(tmp_path / name).codec == codec


def test_a_gap_in_a_sequence_is_refused_where_ffmpeg_would_stop_at_it(shaky, tmp_path):
    pattern = tmp_path / "f%03d.png"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "12", str(pattern)]
    subprocess.run(cmd, check=True)
    assert probe(pattern).width > 0  # 1–12, no gap
    # its rate as given: FFmpeg lists 23.98 for --fps 23.98, which read 24000/1001
    assert probe(pattern, sequence_args(pattern, fps=23.98)).fps == 23.98
    (tmp_path / "f005.png").unlink()
    with pytest.raises(VideoError, match=r"image 5 is missing \(1–4 exist, then 6 on\).* 7 images"):
        probe(pattern)
    # read from after the gap (compare's --start-number), the rest runs on
    assert probe(pattern, sequence_args(pattern, start_number=6)).width > 0


def test_a_phones_photos_held_upright_are_read_and_written_upright(shaky, tmp_path):
    from PIL import Image

    shown = list(read_frames(shaky))[:15]
    for number, frame in enumerate(shown, start=1):
        # stored sideways, with EXIF orientation 6: turn 90° clockwise to show
        photo = Image.fromarray(np.ascontiguousarray(np.rot90(frame, 1)))
        exif = photo.getexif()
        exif[0x0112] = 6
        photo.save(tmp_path / f"IMG_{number:04d}.jpg", exif=exif.tobytes(), quality=95)
    pattern = tmp_path / "IMG_%04d.jpg"
    info = probe(pattern)
    assert info.rotation == 270 and info.size == shown[0].shape[:2]
    upright = next(read_frames(pattern)).astype(int)
    assert np.abs(upright - shown[0]).mean() < 3  # JPEG's loss; before, a garbled frame
    stored = next(read_frames(pattern, info=info.stored())).astype(int)
    assert np.abs(stored - np.rot90(shown[0], 1)).mean() < 3  # the sensor's rows
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(pattern, out, Settings(fov=70.0))
    assert probe(out).size == shown[0].shape[:2] and summary["frames"] == 15


def test_a_clip_whose_name_holds_a_percent_d_is_a_clip(shaky, tmp_path):
    clip = tmp_path / "50%done.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-t", "0.5", "-c", "copy", str(clip)]
    subprocess.run(cmd, check=True)
    assert probe(clip).width > 0  # before, "no file matches this pattern"
    out = tmp_path / "take%d.mp4"  # one video, not a sequence of them
    summary, _ = stabilize_video(clip, out, Settings(fov=70.0))
    assert out.is_file() and probe(out).codec == "h264" and summary["frames"] > 10


def test_an_alpha_plane_left_out_is_said(shaky, tmp_path):
    pattern = tmp_path / "a%03d.png"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "10", "-pix_fmt", "rgba"]
    subprocess.run([*cmd, str(pattern)], check=True)
    summary, _ = stabilize_video(pattern, tmp_path / "out.mp4", Settings(fov=70.0))
    assert any("alpha (transparency, rgba) is left out" in n for n in summary["notices"])


def test_a_percent_in_a_folders_or_files_name_is_not_a_frame_number(shaky, tmp_path):
    # FFmpeg took each for a number's place: the input was "not found", the output's
    # every picture "the same name"; Python's % refused the folder's as a format
    source = tmp_path / "50% off" / "img%-%03d.png"
    source.parent.mkdir()
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "12"]
    subprocess.run([*cmd, str(source).replace("%-", "%%-").replace("50%", "50%%")], check=True)
    assert sorted(sequence_files(source)) == list(range(1, 13))
    out = tmp_path / "a100%b" / "f%04d.png"
    summary, _ = stabilize_video(source, out, Settings())  # --fov auto reads its EXIF
    assert sorted(sequence_files(out)) == list(range(1, 13)) and summary["frames"] == 12
    assert len(list(read_frames(out))) == 12


@pytest.mark.parametrize("orientation", range(1, 9))
def test_every_exif_orientation_is_shown_as_photo_viewers_show_it(tmp_path, orientation):
    # the mirrored ones (2, 4, 5, 7: a front camera's, saved as its preview showed it)
    # were left as stored
    from PIL import Image, ImageOps

    from stabilize.video.turn import turn

    rng = np.random.default_rng(orientation)
    stored = rng.integers(0, 256, (3, 48, 64, 3), dtype=np.uint8)  # no symmetry to hide in
    for number, frame in enumerate(stored, start=1):
        photo = Image.fromarray(frame)
        exif = photo.getexif()
        exif[0x0112] = orientation
        photo.save(tmp_path / f"p{number}.png", exif=exif.tobytes())
    with Image.open(tmp_path / "p1.png") as first:
        viewed = np.asarray(ImageOps.exif_transpose(first).convert("RGB"))
    pattern = tmp_path / "p%d.png"
    info = probe(pattern)
    raw = info.stored()
    np.testing.assert_array_equal(next(read_frames(pattern, info=raw)), stored[0])
    np.testing.assert_array_equal(turn(stored[0], raw.turns, mirror=raw.mirrored), viewed)
    np.testing.assert_array_equal(next(read_frames(pattern, info=info)), viewed)


def test_a_pattern_names_only_the_pictures_ffmpeg_names_so(tmp_path):
    for name in ("0001.png", "001.png", "1.png", "10000.png"):
        (tmp_path / name).write_bytes(b"")
    found = {spec: sorted(p.name for p in sequence_files(tmp_path / f"{spec}.png").values())
             for spec in ("%04d", "%4d", "%03d", "%d")}  # fmt: skip
    # FFmpeg pads %4d with zeros too, where C's printf pads it with spaces
    assert found == {
        "%04d": ["0001.png", "10000.png"],
        "%4d": ["0001.png", "10000.png"],
        "%03d": ["001.png", "10000.png"],
        "%d": ["1.png", "10000.png"],
    }


def test_the_inputs_pictures_are_never_replaced(shaky, tmp_path):
    # %03d's --overwrite deleted the input's 0001.png…, and %4d's pictures, which FFmpeg
    # names 0001.png…, were written over them
    source = tmp_path / "%04d.png"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "8", str(source)]
    subprocess.run(cmd, check=True)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    stabilize_video(source, tmp_path / "%03d.png", Settings(fov=70.0), overwrite=True)
    with pytest.raises(ValueError, match=r"would replace the input's pictures \(0001.png and"):
        stabilize_video(source, tmp_path / "%4d.png", Settings(fov=70.0), overwrite=True)
    assert {name: (tmp_path / name).read_bytes() for name in before} == before
    assert len(sequence_files(tmp_path / "%03d.png")) == 8
