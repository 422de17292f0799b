"""``stabilize rotations``: the rotations file."""

import subprocess

from typer.testing import CliRunner

from stabilize.cli import app
from stabilize.video import ffmpeg_exe, frame_times
from tests.stabilize.helpers import damaged, held_upright


def test_rotations_command(shaky, tmp_path):
    out = tmp_path / "rot.csv"
    result = CliRunner().invoke(app, ["rotations", str(shaky), "-o", str(out), "-q", "--fov", "70"])
    assert result.exit_code == 0, result.output
    lines = out.read_text().splitlines()
    assert lines[0] == "frame,t,rx,ry,rz,support,cut" and len(lines) == 60
    assert all(line.endswith(",0") for line in lines[1:])  # one shot


def test_standard_output_takes_the_rotations_and_the_gcsv(shaky, tmp_path):
    # '-' was a file named '-'
    clip = tmp_path / "three.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "3", str(clip)]
    subprocess.run(cmd, check=True)
    for option, first in (("-o", "frame,t,rx,ry,rz,support,cut"), ("--gcsv", "GYROFLOW IMU LOG")):
        result = CliRunner().invoke(app, ["rotations", str(clip), option, "-", "--fov", "70"])
        assert result.exit_code == 0, result.output
        assert result.stdout.splitlines()[0] == first and len(result.stdout.splitlines()) > 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["three.mp4"]


def test_a_damaged_clip_gives_the_rotations_of_the_frames_that_decode(shaky, tmp_path):
    out = tmp_path / "rot.csv"
    args = ["rotations", str(damaged(shaky, tmp_path)), "-o", str(out), "--fov", "70"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output  # it was refused, as damaged
    decoded = len(frame_times(tmp_path / "damaged.ts", decoded=True))
    assert f"the {decoded} that do are used" in result.output
    assert len(out.read_text().splitlines()) == decoded  # the header, and a row a pair


def test_a_clip_held_upright_gives_its_sensors_rotations(shaky, tmp_path):
    # the sensor's axes, which a gyro is fixed to, however the camera was held
    files = []
    for clip in (shaky, held_upright(shaky, tmp_path)):
        out = tmp_path / f"{clip.stem}.csv"
        args = ["rotations", str(clip), "-o", str(out), "-q", "--focal", "300"]
        assert CliRunner().invoke(app, args).exit_code == 0
        files.append(out.read_text())
    assert files[1] == files[0]


def test_the_output_never_replaces_the_input(shaky, tmp_path):
    # -o clip.mp4 --overwrite replaced the clip with its CSV
    clip = tmp_path / "clip.mp4"
    clip.write_bytes(shaky.read_bytes())
    link = tmp_path / "link.mp4"
    link.symlink_to(clip)
    for args in (["-o", str(clip)], ["--gcsv", str(link)]):
        result = CliRunner().invoke(app, ["rotations", str(clip), *args, "--overwrite", "-q"])
        assert result.exit_code == 2 and "is the input" in result.output
    same = ["-o", str(tmp_path / "r.csv"), "--gcsv", str(tmp_path / "r.csv")]
    result = CliRunner().invoke(app, ["rotations", str(clip), *same, "-q"])
    assert result.exit_code == 2 and "give each its own file" in result.output
    assert clip.read_bytes() == shaky.read_bytes()
