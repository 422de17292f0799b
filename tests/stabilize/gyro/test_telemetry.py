"""Camera-embedded gyro (telemetry-parser) against the independently extracted CSVs."""

import numpy as np
import pytest

from stabilize.gyro import GyroError, detect_format, read_gyro

telemetry_parser = pytest.importorskip("telemetry_parser", reason="the 'telemetry' extra is absent")


@pytest.mark.parametrize("clip", ["karma", "hero7", "max-heromode"])
def test_gopro_gyro_matches_the_extracted_csv(shared, clip):
    video = shared / "data" / "gopro" / f"{clip}.mp4"
    assert detect_format(video) == "telemetry"
    log = read_gyro(video)
    ref = np.loadtxt(
        shared / "data" / "gopro" / "extracted" / f"{clip}_GYRO.csv", delimiter=",", skiprows=1
    )
    assert abs(log.rate_hz - 1 / np.median(np.diff(ref[:, 0]))) / log.rate_hz < 0.05
    # The same samples in the same units: the speeds |ω| agree one for one. (Axes are
    # normalised per camera model by telemetry-parser, not by the quick parser.)
    n = min(len(log.rates), len(ref))
    ours = np.sort(np.linalg.norm(log.rates, axis=1))[-n:]
    theirs = np.sort(np.linalg.norm(ref[:, 1:], axis=1))[-n:]
    np.testing.assert_allclose(ours, theirs, atol=1e-4)
    if clip == "karma":  # HERO5: the same axis order as the raw stream, sample by sample
        np.testing.assert_allclose(log.rates[:50], ref[:50, 1:], atol=1e-5)


def test_a_file_without_telemetry_is_a_clear_error(tmp_path):
    path = tmp_path / "plain.mp4"
    path.write_bytes(b"\x00" * 1000)
    with pytest.raises(GyroError, match="telemetry"):
        read_gyro(path)


@pytest.mark.parametrize(
    ("clip", "says"),
    # hero7's speeds barely correlate with its gyro's (0.11); max-heromode's do (0.90),
    # but its video turns 17% as much as its gyro
    [("hero7", "barely agree"), ("max-heromode", "turns only 17% as much")],
)
def test_in_camera_stabilisation_raises_the_warning(shared, clip, says):
    from typer.testing import CliRunner

    from stabilize.cli import app

    video = shared / "data" / "gopro" / f"{clip}.mp4"
    result = CliRunner().invoke(app, ["compare", str(video), "--gyro", str(video), "-q"])
    assert result.exit_code == 0, result.output
    assert "WARNING" in result.output and "stabilised in the camera" in result.output
    assert says in result.output
