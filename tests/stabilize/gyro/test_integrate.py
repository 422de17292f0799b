import json

import numpy as np
import pytest

from rotation import so3
from stabilize.gyro import GyroError, GyroLog, integrate_rotations, read_opencamera
from stabilize.gyro.integrate import attitude
from stabilize.motion.files import read_rotations
from tests.stabilize.helpers import SAMPLE


def test_gyro_log_integrated_with_the_truth_offset_and_axes_reproduces_truth():
    meta = json.loads((SAMPLE / "truth.json").read_text())
    log = read_opencamera(SAMPLE / "gyro.csv")
    assert log.rate_hz == pytest.approx(meta["gyro_rate"], rel=1e-6)
    unbiased = GyroLog(log.times, log.rates - np.array(meta["gyro_bias"]), log.source)
    truth = read_rotations(SAMPLE / "truth.csv")
    times = np.arange(meta["n_frames"]) / meta["fps"]
    R = integrate_rotations(unbiased, times, meta["offset_s"], np.array(meta["R_cam_imu"]))
    R_true = so3.exp_so3(np.array([truth[k] for k in range(len(R))]))
    assert so3.angular_error_deg(R, R_true).mean() < 0.01
    # The wrong axes or offset are far off: the test can fail.
    wrong = integrate_rotations(unbiased, times, meta["offset_s"], np.eye(3))
    assert so3.angular_error_deg(wrong, R_true).mean() > 0.1


def test_constant_rate_integrates_to_the_exponential():
    t = np.linspace(0, 1, 401)
    w = np.array([0.3, -0.2, 0.5])
    log = GyroLog(t, np.tile(w, (len(t), 1)), "const")
    R = integrate_rotations(log, np.array([0.1, 0.35, 0.6]))
    np.testing.assert_allclose(R[0], so3.exp_so3(-w * 0.25), atol=1e-12)


def test_a_log_shorter_than_the_video_is_refused():
    log = GyroLog(np.linspace(0, 1, 100), np.zeros((100, 3)), "short")
    with pytest.raises(GyroError, match="covers"):
        integrate_rotations(log, np.array([0.5, 1.5]))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "no gyro samples"),
        ("0.1,0.2,0.3,100\n0.1,0.2,0.3,50\n", "does not increase"),
        ("0.1,0.2,100\n", "expected 4"),
        ("0.1,0.2,x,100\n", "not a number"),
    ],
)
def test_bad_opencamera_logs(tmp_path, text, message):
    path = tmp_path / "gyro.csv"
    path.write_text(text)
    with pytest.raises(GyroError, match=message):
        read_opencamera(path)


def test_attitude_between_any_two_times_matches_the_sampled_rates():
    t = np.linspace(0, 1, 201)
    rates = np.stack([np.sin(3 * t), 0.5 * t, np.cos(2 * t)], -1)
    att = attitude(GyroLog(t, rates, "smooth"))
    np.testing.assert_allclose(att.at(t[[0, 50]]), att.G[[0, 50]], atol=1e-12)
    # Between sample times, and inside one sample interval, against a fine integration.
    fine = np.linspace(0, 1, 20001)
    fine_att = attitude(
        GyroLog(fine, np.stack([np.sin(3 * fine), 0.5 * fine, np.cos(2 * fine)], -1))
    )
    a, b = np.array([0.1234, 0.5001]), np.array([0.4567, 0.5031])
    err = so3.angular_error_deg(att.between(a, b), fine_att.between(a, b))
    # The exponent is not corrected for non-commuting rates: 3e-4° over 0.33 s here.
    assert err[0] < 1e-3 and err[1] < 1e-5


def test_lag_shifts_each_interval():
    t = np.linspace(0, 2, 801)
    rates = np.stack([t, np.zeros_like(t), np.zeros_like(t)], -1)  # a ramp about x
    log = GyroLog(t, rates, "ramp")
    frames = np.array([0.5, 0.6, 0.7])
    lagged = integrate_rotations(log, frames, lag=np.array([0.02, 0.05]))
    np.testing.assert_allclose(
        lagged[0], integrate_rotations(log, frames[:2] + 0.02)[0], atol=1e-12
    )
    angle = np.degrees(so3.angle(lagged[1]))  # ∫ t dt over [0.65, 0.75]
    assert angle == pytest.approx(np.degrees(0.5 * (0.75**2 - 0.65**2)), rel=1e-9)


def test_a_log_a_frame_short_at_an_end_holds_its_end_rate():
    # a camera's log that starts 53 ms after the first frame (GoPro karma.mp4)
    t = np.linspace(0.053, 2.0, 400)
    w = np.array([0.3, -0.2, 0.5])
    log = GyroLog(t, np.tile(w, (len(t), 1)), "late")
    R = integrate_rotations(log, np.array([0.0, 1 / 30, 2 / 30]))
    np.testing.assert_allclose(R[0], so3.exp_so3(-w / 30), atol=1e-9)
    bumped = log.rates.copy()  # one sample off: held, the edge turns by the first rate
    bumped[1] += [0.05, 0.0, 0.0]
    R = integrate_rotations(GyroLog(t, bumped, "bumped"), np.array([0.0, 0.053]))
    np.testing.assert_allclose(R[0], so3.exp_so3(-w * 0.053), atol=1e-9)
    with pytest.raises(GyroError, match="covers"):  # half a second short is refused
        integrate_rotations(GyroLog(t + 0.5, log.rates, "later"), np.array([0.0, 1 / 30]))
