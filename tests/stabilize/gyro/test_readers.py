"""Each reader on small fixture files written here, and the errors for bad logs."""

import os

import numpy as np
import pytest

from stabilize.gyro import GyroError, detect_format, read_gyro
from stabilize.gyro.readers import read_frame_timestamps_ns, read_frame_timestamps_s

RATES = np.array([[0.1, -0.2, 0.3], [0.15, -0.25, 0.35], [0.2, -0.3, 0.4]])


def write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_opencamera(tmp_path):
    path = write(
        tmp_path,
        "gyro.csv",
        "".join(
            f"{x},{y},{z},{1_000_000_000 + 2_500_000 * k}\n" for k, (x, y, z) in enumerate(RATES)
        ),
    )
    assert detect_format(path) == "opencamera"
    log = read_gyro(path)
    np.testing.assert_allclose(log.rates, RATES)
    np.testing.assert_allclose(log.times, [1.0, 1.0025, 1.005])
    assert log.rate_hz == pytest.approx(400.0)


def test_phone_cc9(tmp_path):
    path = write(
        tmp_path,
        "gyro.txt",
        "".join(
            f"{x:.18e},{y:.18e},{z:.18e},{4.3e6 + k / 400:.18e}\n"
            for k, (x, y, z) in enumerate(RATES)
        ),
    )
    assert detect_format(path) == "phone-cc9"
    np.testing.assert_allclose(read_gyro(path).rates, RATES)
    stamps = write(tmp_path, "framestamp.txt", "4.3e6\n4.3000333e6\n")
    np.testing.assert_allclose(read_frame_timestamps_s(stamps), [4.3e6, 4.3000333e6])
    ns = write(tmp_path, "timestamps.csv", "100\n200\n")
    np.testing.assert_allclose(read_frame_timestamps_ns(ns), [1e-7, 2e-7])


def test_gcsv_scales_and_orientation(tmp_path):
    lines = [
        "GYROFLOW IMU LOG",
        "version,1.3",
        "id,test",
        "orientation,yXz",
        "tscale,0.001",
        "gscale,0.5",
        "frame_readout_time,15.23",
        "frame_readout_direction,0",
        "t,gx,gy,gz",
    ]
    lines += [f"{10 * k},{2 * x},{2 * y},{2 * z}" for k, (x, y, z) in enumerate(RATES)]
    path = write(tmp_path, "log.gcsv", "\n".join(lines) + "\n")
    assert detect_format(path) == "gcsv"
    log = read_gyro(path)
    np.testing.assert_allclose(log.times, [0.0, 0.01, 0.02])
    # columns are (-y, x, -z) of the sensor: sensor x = gy, y = -gx, z = -gz
    np.testing.assert_allclose(log.rates, np.c_[RATES[:, 1], -RATES[:, 0], -RATES[:, 2]])
    assert log.readout_s == pytest.approx(0.01523)


def test_sensor_logger_reads_columns_by_name(tmp_path):
    text = "time,seconds_elapsed,z,y,x\n" + "".join(
        f"{1_700_000_000_000_000_000 + k},{0.01 * k},{z},{y},{x}\n"
        for k, (x, y, z) in enumerate(RATES)
    )
    path = write(tmp_path, "Gyroscope.csv", text)
    log = read_gyro(path)
    np.testing.assert_allclose(log.rates, RATES)
    np.testing.assert_allclose(log.times, [0.0, 0.01, 0.02])


def test_plain_csv_with_units(tmp_path):
    text = "t_ms,wx,wy,wz\n" + "".join(
        f"{5 * k},{np.degrees(x)},{np.degrees(y)},{np.degrees(z)}\n"
        for k, (x, y, z) in enumerate(RATES)
    )
    path = write(tmp_path, "imu.csv", text)
    log = read_gyro(path, time_column="t_ms", time_unit="ms", rate_unit="deg/s")
    np.testing.assert_allclose(log.rates, RATES)
    np.testing.assert_allclose(log.times, [0.0, 0.005, 0.01])


def test_phyphox_export_units_from_its_header(tmp_path):
    # phyphox's "Gyroscope" experiment, exported as CSV (comma, decimal point)
    head = '"Time (s)","Gyroscope x (rad/s)","Gyroscope y (rad/s)","Gyroscope z (rad/s)",'
    text = (
        head
        + '"Absolute (rad/s)"\n'
        + "".join(
            f"{0.01 * k:.9E},{x:.9E},{y:.9E},{z:.9E},{np.linalg.norm([x, y, z]):.9E}\n"
            for k, (x, y, z) in enumerate(RATES)
        )
    )
    path = write(tmp_path, "Raw Data.csv", "\ufeff" + text)  # with a byte-order mark
    assert detect_format(path) == "csv"
    log = read_gyro(path)
    np.testing.assert_allclose(log.rates, RATES)
    np.testing.assert_allclose(log.times, [0.0, 0.01, 0.02])


def test_a_spreadsheets_csv_with_decimal_commas_and_units_in_brackets(tmp_path):
    # semicolons between fields, commas for decimals, as a German or French locale writes
    text = "time [ms];gx [deg/s];gy [deg/s];gz [deg/s]\n" + "".join(
        f"{5 * k};{np.degrees(x):.6f};{np.degrees(y):.6f};{np.degrees(z):.6f}\n".replace(".", ",")
        for k, (x, y, z) in enumerate(RATES)
    )
    log = read_gyro(write(tmp_path, "imu.csv", text))
    np.testing.assert_allclose(log.rates, RATES, atol=1e-7)
    np.testing.assert_allclose(log.times, [0.0, 0.005, 0.01])


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("empty.csv", "", "no gyro samples"),
        ("back.csv", "0.1,0.2,0.3,100\n0.1,0.2,0.3,50\n", "does not increase"),
        ("short.csv", "0.1,0.2,0.3,100\n0.1,0.2,200\n", r"short\.csv:2: expected 4"),
        ("word.csv", "0.1,0.2,0.3,100\n0.1,0.2,x,200\n", r"word\.csv:2: not a number"),
        ("cols.csv", "t,a,b\n0,1,2\n", "no column named"),
        ("odd.csv", "1,2,3\n", "unknown gyro log layout"),
    ],
)
def test_bad_logs_name_the_line_and_problem(tmp_path, name, text, message):
    path = write(tmp_path, name, text)
    with pytest.raises(GyroError, match=message):
        read_gyro(path)


def test_unreadable_log(tmp_path):
    with pytest.raises(GyroError, match="no such gyro log"):
        read_gyro(tmp_path / "missing.csv")
    os.mkfifo(tmp_path / "piped.csv")  # a log read more than once: <(cat log) read "no such"
    for where in (tmp_path / "piped.csv", tmp_path):
        with pytest.raises(GyroError, match="not a file: save the log first"):
            read_gyro(where)
