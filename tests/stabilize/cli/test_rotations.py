"""``stabilize rotations``: the rotations file."""

from typer.testing import CliRunner

from stabilize.cli import app


def test_rotations_command(shaky, tmp_path):
    out = tmp_path / "rot.csv"
    result = CliRunner().invoke(app, ["rotations", str(shaky), "-o", str(out), "-q", "--fov", "70"])
    assert result.exit_code == 0, result.output
    lines = out.read_text().splitlines()
    assert lines[0] == "frame,t,rx,ry,rz,support" and len(lines) == 60
