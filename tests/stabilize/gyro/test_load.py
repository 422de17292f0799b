"""What a gyro path starts from: the log --gyro auto finds, and the readout and where it
comes from."""

import pytest

from stabilize.gyro import GyroError
from stabilize.gyro.load import find_gyro_log, gyro_log_for, readout_seconds, starting_readout


@pytest.mark.parametrize(
    ("option", "log", "lens", "wanted"),
    [
        (20.0, 0.03, 0.01, (0.02, "given")),  # the option over the log's and the profile's
        (0.0, 0.03, None, (0.0, "given")),  # --rolling-shutter off
        ("auto", 0.03, None, (None, "estimated")),  # estimated even where the log gives one
        (None, 0.03, 0.01, (0.03, "log")),
        (None, 0.0, 0.01, (0.0, "log")),  # a log that says global shutter means it
        (None, None, 0.01, (0.01, "lens")),
        (None, None, None, (None, "estimated")),  # was 0: no correction, unsaid
    ],
)
def test_the_readout_comes_from_the_option_else_the_log_else_the_profile(option, log, lens, wanted):
    assert starting_readout(option, log, lens) == wanted


def test_a_readout_out_of_range_is_refused():
    with pytest.raises(ValueError, match="between 0 and 1000 ms"):
        readout_seconds(1500.0)


NOTES = "Beach, day 2: the second take is the good one\n"


@pytest.mark.parametrize(
    ("name", "text", "taken"),
    [
        ("clip.txt", NOTES, False),  # the clip's notes: the clip was refused for them
        ("clip.csv", "start,end,text\n0,2,hello\n", False),  # captions, not rates
        ("clip.txt", "0.01,0.02,0.03,100000000\n", True),  # OpenCamera's four numbers
        ("clip.csv", "t,gx,gy,gz\n0,0.01,0.02,0.03\n", True),
        ("clip.gcsv", "", True),  # a Gyroflow log by its name: refused when read, not passed
    ],
    ids=["notes", "captions", "four numbers", "named columns", "empty gcsv"],
)
def test_auto_takes_the_log_beside_a_clip_not_its_notes(tmp_path, name, text, taken):
    clip = tmp_path / "clip.mp4"
    clip.write_bytes(b"not a camera's file")
    (tmp_path / name).write_text(text)
    assert find_gyro_log(clip) == (tmp_path / name if taken else None)


def test_a_clip_with_notes_and_no_log_is_said_to_have_none(tmp_path):
    clip = tmp_path / "clip.mp4"
    clip.write_bytes(b"not a camera's file")
    (tmp_path / "clip.txt").write_text(NOTES)
    with pytest.raises(
        GyroError, match=r"no gyro log beside .* \(clip.txt beside it: no gyro log\)"
    ):
        gyro_log_for(clip)
