"""The readout a gyro path starts from, and where it comes from."""

import pytest

from stabilize.gyro.load import readout_seconds, starting_readout


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
