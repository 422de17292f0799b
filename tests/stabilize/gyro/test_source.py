import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rotation import so3
from stabilize import Settings, stabilize_video
from stabilize.cli import app
from stabilize.evaluate.metrics import evaluate
from stabilize.gyro import GyroError, GyroLog, read_gyro
from stabilize.gyro.export import write_gcsv
from stabilize.gyro.load import lowpass
from stabilize.gyro.sync import visual_rates
from stabilize.video import read_frames
from tests.stabilize.helpers import SAMPLE, held_upright


def sample_log(path, gain: float = 1.0, shift_ns: int = 0, source=SAMPLE / "gyro.csv"):
    """The sample's gyro log (x, y, z rad/s, t ns), or ``source``'s, written to ``path``
    with its rates times ``gain`` and its clock ``shift_ns`` later."""
    rows = (line.split(",") for line in source.read_text().splitlines())
    path.write_text(
        "".join(
            f"{gain * float(x)},{gain * float(y)},{gain * float(z)},{int(t) + shift_ns}\n"
            for x, y, z, t in rows
        )
    )
    return path


def test_gcsv_export_round_trips_through_the_reader(tmp_path):
    times = np.arange(6) / 30.0
    R = so3.exp_so3(np.array([[0.01, -0.02, 0.005]] * 5))
    write_gcsv(tmp_path / "v.gcsv", times, R)
    log = read_gyro(tmp_path / "v.gcsv")
    np.testing.assert_allclose(log.rates, visual_rates(times, R), atol=1e-8)
    np.testing.assert_allclose(log.times, 0.5 * (times[1:] + times[:-1]), atol=1e-6)


def test_lowpass_removes_high_frequencies():
    t = np.arange(0, 2, 1 / 400)
    slow, fast = np.sin(2 * np.pi * 2 * t), np.sin(2 * np.pi * 80 * t)
    log = GyroLog(t, np.stack([slow + fast] * 3, -1), "test")
    out = lowpass(log, 20.0)
    assert np.abs(out.rates[100:-100, 0] - slow[100:-100]).max() < 0.05
    with pytest.raises(GyroError, match="between"):
        lowpass(log, 500.0)


def test_stabilising_from_the_gyro_beside_the_clip(tmp_path):
    # --gyro auto, as batch's: the log of the clip's name (it was "auto: no such gyro log")
    clip, out = tmp_path / "clip.mp4", tmp_path / "gyro.mp4"
    clip.write_bytes((SAMPLE / "clip.mp4").read_bytes())
    (tmp_path / "clip.csv").write_bytes((SAMPLE / "gyro.csv").read_bytes())
    result = CliRunner().invoke(
        app,
        [
            "run",
            str(clip),
            str(out),
            "--gyro",
            "auto",
            "--fov",
            "70",
            "--gyro-lpf",
            "40",
            "-q",
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert abs(summary["gyro"]["offset_s"] - 0.35) < 1e-3
    assert abs(summary["gyro"]["motion_scale"] - 1) < 0.05
    assert summary["frames"] == 90 and out.is_file()
    # a global shutter, its readout estimated against the gyro: not the 0.5 ms it read
    # (within 3σ of none), which corrected its rows by it
    assert summary["gyro"]["readout_source"] == "estimated"
    assert summary["gyro"]["readout_ms"] == 0.0
    assert "rolling shutter: global shutter (estimated against the gyro)" in summary["notices"]


def test_gyro_auto_with_no_log_beside_or_in_the_clip_is_refused(tmp_path):
    out = tmp_path / "o.mp4"
    pattern = str(tmp_path / "img-%d.jpg")
    for clip, said in ((str(SAMPLE / "clip.mp4"), "no gyro log beside"), (pattern, "sequence")):
        for command in (["run", clip, str(out)], ["compare", clip]):
            result = CliRunner().invoke(app, [*command, "--gyro", "auto"])
            assert result.exit_code == 2 and said in result.output, result.output
    assert not out.exists()


def test_frame_times_on_the_gyro_clock_and_a_log_on_its_own(tmp_path):
    # timestamps.csv dates the frames on the gyro's clock (ns): the offset is then ~0.
    out = tmp_path / "stamped.mp4"
    args = ["run", str(SAMPLE / "clip.mp4"), str(out), "--gyro", str(SAMPLE / "gyro.csv")]
    args += ["--gyro-timestamps", str(SAMPLE / "timestamps.csv"), "--fov", "70", "-q", "--json"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    gyro = json.loads(result.stdout)["gyro"]
    assert abs(gyro["offset_s"]) < 2e-3 and not gyro["searched_whole_log"]
    # The same log on a boot clock 123456 s in: found by searching its whole span.
    shifted = sample_log(tmp_path / "boot.csv", shift_ns=123456 * 10**9)
    args = ["run", str(SAMPLE / "clip.mp4"), str(tmp_path / "boot.mp4"), "--gyro", str(shifted)]
    result = CliRunner().invoke(app, [*args, "--fov", "70", "-q", "--json"])
    assert result.exit_code == 0, result.output
    gyro = json.loads(result.stdout)["gyro"]
    meta = json.loads((SAMPLE / "truth.json").read_text())
    assert gyro["searched_whole_log"]
    assert abs(gyro["offset_s"] - 123456.0 - meta["offset_s"]) < 2e-3


def noise_log(path):
    """A 5 s gyro log of white noise (OpenCamera's layout), which no video's motion
    matches."""
    rng = np.random.default_rng(1)
    t = np.arange(0, 5, 1 / 400)
    path.write_text(
        "".join(
            f"{x},{y},{z},{round(s * 1e9)}\n"
            for (x, y, z), s in zip(rng.normal(0, 0.3, (len(t), 3)), t, strict=True)
        )
    )
    return path


def test_a_mismatched_gyro_is_refused(tmp_path):
    path = noise_log(tmp_path / "noise.csv")
    out = tmp_path / "o.mp4"
    result = CliRunner().invoke(
        app, ["run", str(SAMPLE / "clip.mp4"), str(out), "--gyro", str(path), "-q"]
    )
    assert result.exit_code != 0 and "does not match" in result.output
    assert not out.exists()


def test_a_mismatched_gyro_may_give_way_to_the_video(shaky, tmp_path):
    # batch --gyro auto's for a camera's own gyro, which a clip it steadied (a GoPro's
    # HyperSmooth) does not match: that clip failed, where it was stabilised without
    said: list[str] = []
    log = str(noise_log(tmp_path / "noise.csv"))
    settings = Settings(fov=70.0, gyro=log, gyro_fallback=True)
    summary, planned = stabilize_video(shaky, tmp_path / "g.mp4", settings, notify=said.append)
    _, visual = stabilize_video(shaky, tmp_path / "v.mp4", Settings(fov=70.0))
    assert summary["gyro"] is None and summary["frames"] == 60
    assert any(n.startswith("gyro: not used, the gyro's motion does not match") for n in said)
    assert [n for n in said if n.startswith("gyro")] == [
        n for n in summary["notices"] if n.startswith("gyro")
    ]  # --json's summary says what the run said (it held what was said before the work)
    assert np.allclose(planned.corrections(), visual.corrections())  # as without the log
    # one that turns 3 times as far as the video (max-heromode's: 6 times) gives way too
    thrice = sample_log(tmp_path / "thrice.csv", 3.0, source=shaky.parent / "gyro.csv")
    settings = replace(settings, gyro=str(thrice))
    summary, planned = stabilize_video(shaky, tmp_path / "t.mp4", settings, notify=said.append)
    assert summary["gyro"] is None
    assert any(n.startswith("gyro: not used, the video turns 0.3") for n in said)
    assert np.allclose(planned.corrections(), visual.corrections())


@pytest.mark.parametrize(
    ("gain", "refused", "says"),
    [
        # degrees per second where the format says radians: no focal length explains it
        (np.degrees(1.0), True, "another unit"),
        # three times the turn the video shows: a clip stabilised in the camera, say
        (3.0, False, "the video turns 0.34 times as far as its gyro"),
    ],
)
def test_a_gyro_that_turns_far_more_than_the_video_is_said_or_refused(
    tmp_path, gain, refused, says
):
    scaled = sample_log(tmp_path / "scaled.csv", gain=gain)
    out = tmp_path / "o.mp4"
    args = ["run", str(SAMPLE / "clip.mp4"), str(out), "--gyro", str(scaled), "--fov", "70"]
    result = CliRunner().invoke(app, [*args, "-q"])
    assert (result.exit_code != 0) == refused and says in result.output
    assert out.exists() != refused


def test_rotations_gcsv_option(tmp_path):
    result = CliRunner().invoke(
        app, ["rotations", str(SAMPLE / "clip.mp4"), "--gcsv", str(tmp_path / "c.gcsv"), "-q"]
    )
    assert result.exit_code == 0, result.output
    assert read_gyro(tmp_path / "c.gcsv").rates.shape == (89, 3)


def test_rolling_shutter_correction_from_the_gyro(tmp_path):
    out = tmp_path / "rs.mp4"
    args = ["run", str(SAMPLE / "clip.mp4"), str(out), "--gyro", str(SAMPLE / "gyro.csv")]
    result = CliRunner().invoke(app, [*args, "--fov", "70", "--readout-ms", "20", "-q", "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)  # notices go to stderr
    assert summary["gyro"]["readout_ms"] == 20.0 and summary["frames"] == 90
    # Given a readout, the offset found is the first row's: the content's (0.35 s, a global
    # shutter) minus the readout times the mean height of the vectors, which is 0..1.
    assert 0.35 - 0.020 < summary["gyro"]["offset_s"] < 0.35 - 0.002


def test_a_clip_held_upright_is_stabilised_from_the_gyro_as_held_level(tmp_path):
    # worked on as its sensor stored it: the same rows, offset and axes as held level
    upright = held_upright(SAMPLE / "clip.mp4", tmp_path)
    args = ["--gyro", str(SAMPLE / "gyro.csv"), "--focal", "554", "--readout-ms", "20"]
    gyro = []
    for clip in (SAMPLE / "clip.mp4", upright):
        out = tmp_path / f"{clip.stem}_out.mp4"
        result = CliRunner().invoke(app, ["run", str(clip), str(out), *args, "-q", "--json"])
        assert result.exit_code == 0, result.output
        gyro.append(json.loads(result.stdout)["gyro"])
    assert gyro[1] == gyro[0] and gyro[1]["readout_ms"] == 20.0


def test_readout_needs_the_gyro(tmp_path):
    out = tmp_path / "o.mp4"
    result = CliRunner().invoke(
        app, ["run", str(SAMPLE / "clip.mp4"), str(out), "--readout-ms", "20", "-q"]
    )
    assert result.exit_code != 0 and "--gyro" in result.output and not out.exists()


def test_a_readout_no_log_gives_is_estimated_against_the_gyro(rolling_clip, tmp_path):
    # a log that gives no readout (phone-cc9's, a GoPro's) was taken for a global
    # shutter, and nothing was corrected: phone-cc9 read 1.181 px of residual shake so,
    # 1.082 at the 23.4 ms found against its gyro
    told: list[str] = []
    settings = Settings(gyro=rolling_clip / "gyro.csv", fov=70.0)
    summary, planned = stabilize_video(
        rolling_clip / "clip.mp4", tmp_path / "out.mp4", settings, notify=told.append
    )
    gyro = summary["gyro"]
    assert gyro["readout_source"] == "estimated" and gyro["readout_ms"] == pytest.approx(25, abs=4)
    assert planned.row_corrections is not None
    assert any(t.startswith("rolling shutter: ") and "against the gyro" in t for t in told)


def test_a_readout_the_gyro_does_not_pin_down_is_read_from_the_video(rolling_clip, tmp_path):
    # with the offset given, the bands are not dated against the gyro (nor are karma's,
    # whose smooth flight dates them poorly; its video reads 34.9 ms): the video's own
    # estimate stands in, as it would without the log
    meta = json.loads((rolling_clip / "truth.json").read_text())
    told: list[str] = []
    settings = Settings(gyro=rolling_clip / "gyro.csv", gyro_offset=meta["offset_s"], fov=70.0)
    summary, planned = stabilize_video(
        rolling_clip / "clip.mp4", tmp_path / "out.mp4", settings, notify=told.append
    )
    gyro = summary["gyro"]
    assert gyro["readout_source"] == "video" and gyro["readout_ms"] == pytest.approx(25, abs=2.5)
    assert planned.row_corrections is not None
    assert any("from the video (the gyro does not pin it down)" in t for t in told)
    # a readout given is used as it is: at 0 the rows wobble (1.56 px, against 1.08)
    settings = replace(settings, readout_ms=0.0)
    summary, planned = stabilize_video(rolling_clip / "clip.mp4", tmp_path / "off.mp4", settings)
    assert summary["gyro"]["readout_source"] == "given" and planned.row_corrections is None

    def wobble(output: Path) -> float:  # the output's own (the original's is not needed)
        return evaluate(read_frames(output)).wobble_px

    assert wobble(tmp_path / "out.mp4") < 0.8 * wobble(tmp_path / "off.mp4")
