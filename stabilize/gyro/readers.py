"""Readers for gyro log formats. Each gives a :class:`GyroLog` in rad/s and seconds,
in the sensor's own axes. :func:`read_gyro` detects the format from the file.

* ``opencamera``: OpenCamera Sensors, ``x,y,z,t_ns`` per line, no header.
* ``phone-cc9``: ``wx,wy,wz,t`` (rad/s, s), no header (the phone-cc9 data set).
* ``gcsv``: Gyroflow's ``.gcsv`` v1.x: a ``GYROFLOW IMU LOG`` header of ``key,value``
  lines (``tscale``, ``gscale``, ``orientation``, ...), then ``t,gx,gy,gz[,ax,ay,az]``.
* ``sensorlogger``: Sensor Logger's ``Gyroscope.csv``: ``time,seconds_elapsed,z,y,x``
  (columns read by name; ``time`` in ns).
* ``csv``: any CSV with a header naming a time column and x, y, z rate columns (phyphox's
  export among them); units as the header names them in brackets, else options.
* ``telemetry``: gyro embedded in a camera's video file, read by ``telemetry-parser``.
"""

from __future__ import annotations

import csv
import importlib.util
import re
from pathlib import Path

import numpy as np

from stabilize.gyro.axes import axes_matrix
from stabilize.gyro.log import GyroError, GyroLog

TELEMETRY_EXTRA = (
    "the 'telemetry' extra: pip install 'hough-stabilize[telemetry]' (the telemetry-parser package)"
)
GYRO_SIDECARS = (".gcsv", ".csv", ".txt")  # a log beside clip.mp4 (batch --gyro auto)
VIDEO_SUFFIXES = {".mp4", ".mov", ".insv", ".360", ".mxf", ".mkv", ".braw", ".lrv", ".m4v"}
NS_PER_FRAME_AT_LEAST = 1000.0  # a median frame step above this is in nanoseconds
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
RATE_UNITS = {"rad/s": 1.0, "deg/s": np.pi / 180.0}


def _check_file(path: Path) -> None:
    """A GyroError where ``path`` is no file to read: missing, or a pipe (``<(cat log)``),
    which the log's readers would read more than once."""
    if not path.exists():
        raise GyroError(f"{path}: no such gyro log")
    if not path.is_file():
        raise GyroError(f"{path}: is a pipe, a device or a folder, not a file: save the log first")


def _rows(path: Path, n_fields: int, *, start: int = 0) -> list[list[float]]:
    """Numeric CSV rows from line ``start`` on, or a GyroError naming the first bad line."""
    _check_file(path)
    rows = []
    with open(path, errors="replace") as f:
        for number, line in enumerate(f, start=1):
            line = line.strip()
            if number <= start or not line or line.startswith("#"):
                continue
            fields = line.split(",")
            if len(fields) != n_fields:
                raise GyroError(
                    f"{path}:{number}: expected {n_fields} comma-separated fields, "
                    f"got {len(fields)}"
                )
            try:
                rows.append([float(v) for v in fields])
            except ValueError:
                raise GyroError(f"{path}:{number}: not a number in {line!r}") from None
    if not rows:
        raise GyroError(f"{path}: no gyro samples")
    return rows


def read_opencamera(path: str | Path) -> GyroLog:
    """OpenCamera Sensors: ``x,y,z,t_ns`` per line, rad/s, no header."""
    path = Path(path)
    data = np.array(_rows(path, 4))
    return GyroLog(data[:, 3] * 1e-9, data[:, :3], str(path))


def read_phone_cc9(path: str | Path) -> GyroLog:
    """The phone-cc9 layout: ``wx,wy,wz,t`` in rad/s and seconds, no header."""
    path = Path(path)
    data = np.array(_rows(path, 4))
    return GyroLog(data[:, 3], data[:, :3], str(path))


def read_frame_timestamps_ns(path: str | Path) -> np.ndarray:
    """OpenCamera Sensors' frame timestamps: one integer (ns) per line → seconds."""
    return _frame_times(Path(path), 1e-9)


def read_frame_timestamps_s(path: str | Path) -> np.ndarray:
    """phone-cc9's framestamp.txt: one start-of-frame time (s) per line."""
    return _frame_times(Path(path), 1.0)


def first_stamp(start_number: int | None) -> int:
    """The line (0-based) of a timestamps file that dates an image sequence's first image
    ``start_number``: line N dates image N, the first line image 0 or 1; a video (None)
    starts at the first line.

    >>> first_stamp(99), first_stamp(1), first_stamp(0), first_stamp(None)
    (98, 0, 0, 0)
    """
    return max((start_number or 1) - 1, 0)


def sensor_frame_times(path: str | Path, first: int, count: int) -> np.ndarray:
    """``count`` frame times (s, on the sensor's clock) from line ``first`` (0-based) of a
    timestamps file: seconds per line (phone-cc9), or integer nanoseconds (OpenCamera)."""
    stamps = read_frame_timestamps_s(path)
    # A frame interval is under a second; in nanoseconds (OpenCamera) it is millions.
    if len(stamps) > 1 and np.median(np.diff(stamps)) > NS_PER_FRAME_AT_LEAST:
        stamps = stamps * 1e-9
    times = stamps[first : first + count]
    if len(times) < count:
        raise GyroError(f"{path}: {len(stamps)} frame times, the video needs {first + count}")
    return times


def _frame_times(path: Path, scale: float) -> np.ndarray:
    data = np.array(_rows(path, 1))[:, 0] * scale
    if np.any(np.diff(data) <= 0):
        raise GyroError(f"{path}: frame times do not increase")
    return data


def read_gcsv(path: str | Path) -> GyroLog:
    """Gyroflow .gcsv: header fields, ``tscale`` and ``gscale``, ``orientation``, and
    ``frame_readout_time`` (ms, top to bottom) when present.

    ``orientation`` (e.g. ``YxZ``) says which sensor axis each logged column is, a
    lower-case letter meaning the negative axis; rates are returned in sensor axes.
    """
    path = Path(path)
    _check_file(path)
    header: dict[str, str] = {}
    columns: list[str] = []
    with open(path, errors="replace") as f:
        first = f.readline().strip()
        if not first.upper().startswith("GYROFLOW IMU LOG"):
            raise GyroError(f"{path}:1: not a Gyroflow .gcsv (expected 'GYROFLOW IMU LOG')")
        for number, line in enumerate(f, start=2):
            key, _, value = line.strip().partition(",")
            if key == "t":
                columns = [c.strip() for c in line.strip().split(",")]
                start = number
                break
            header[key.strip()] = value.strip()
        else:
            raise GyroError(f"{path}: no 't,gx,gy,gz' column line")
    try:
        tscale = float(header.get("tscale", "1"))
        gscale = float(header.get("gscale", "1"))
    except ValueError:
        raise GyroError(f"{path}: tscale and gscale must be numbers") from None
    for c in ("gx", "gy", "gz"):
        if c not in columns:
            raise GyroError(f"{path}:{start}: no {c} column")
    idx = [columns.index(c) for c in ("t", "gx", "gy", "gz")]
    data = np.array(_rows(path, len(columns), start=start))[:, idx]
    rates = data[:, 1:] * gscale
    try:  # the code names the sensor axis of each column: the transpose of axes_matrix
        columns_to_sensor = axes_matrix(header.get("orientation", "XYZ"), proper=False).T
    except GyroError:
        raise GyroError(f"{path}: orientation must be a signed permutation of XYZ") from None
    rates = rates @ columns_to_sensor.T
    readout = header.get("frame_readout_time")
    try:
        readout_s = float(readout) / 1000.0 if readout else None  # logged in ms
    except ValueError:
        raise GyroError(f"{path}: frame_readout_time must be a number of ms") from None
    if readout_s is not None and header.get("frame_readout_direction", "0") not in ("0", ""):
        readout_s = None  # only top-to-bottom readout is modelled
    return GyroLog(data[:, 0] * tscale, rates, str(path), readout_s)


# Units a header may name in brackets ("Time (s)", "Gyroscope x (rad/s)", "gx [deg/s]")
HEADER_TIME_UNITS = {"s": "s", "sec": "s", "ms": "ms", "us": "us", "µs": "us", "ns": "ns"}
HEADER_RATE_UNITS = {"rad/s": "rad/s", "deg/s": "deg/s", "°/s": "deg/s", "dps": "deg/s"}
_UNIT = re.compile(r"\s*[(\[]([^)\]]*)[)\]]\s*$")
_SENSOR_WORDS = re.compile(r"^(gyroscope|gyro|angular velocity|rotation rate)[\s_]+")


def _column(name: str) -> tuple[str, str]:
    """A header's column name and the unit it names in brackets, normalised:
    ``"Gyroscope x (rad/s)"`` → ``("x", "rad/s")`` (phyphox's export), ``"t"`` → ``("t", "")``.

    >>> _column('"Time (s)"'), _column("Gyroscope x (rad/s)"), _column("gz [deg/s]")
    (('time', 's'), ('x', 'rad/s'), ('gz', 'deg/s'))
    """
    name = name.strip().strip('"').strip().lower()
    unit = _UNIT.search(name)
    if unit:
        name = name[: unit.start()]
    return _SENSOR_WORDS.sub("", name.strip()), unit.group(1).strip() if unit else ""


def _delimiter(header: str) -> str:
    """The header's field separator: ``;`` (a spreadsheet's where the decimal mark is a
    comma), a tab, else a comma."""
    return max((";", "\t"), key=header.count) if ";" in header or "\t" in header else ","


def read_named_csv(
    path: str | Path,
    *,
    time_column: str | None = None,
    columns: tuple[str, str, str] | None = None,
    time_unit: str | None = None,
    rate_unit: str | None = None,
) -> GyroLog:
    """A CSV with a header: the time column and x, y, z rate columns, read by name.

    Sensor Logger's ``Gyroscope.csv`` (``time`` in ns, ``seconds_elapsed``, ``z,y,x``)
    is read with its own names and units when no others are given. Units the header
    names in brackets are used where none is given (phyphox's ``Time (s)``,
    ``Gyroscope x (rad/s)``); else seconds and rad/s. Fields may be separated by commas,
    tabs or semicolons, and where they are not commas the decimal mark may be a comma,
    as a spreadsheet in many languages writes them.
    """
    path = Path(path)
    _check_file(path)
    with open(path, newline="", encoding="utf-8-sig", errors="replace") as f:
        header = f.readline()
        delimiter = _delimiter(header)
        named = [_column(n) for n in next(csv.reader([header], delimiter=delimiter), [])]
        names = [n for n, _ in named]
        wanted = _wanted_columns(names, time_column, columns)
        missing = [c for c in wanted if c not in names]
        if missing:
            raise GyroError(f"{path}:1: no column named {', '.join(missing)} (have {names})")
        idx = [names.index(c) for c in wanted]
        units = [named[i][1] for i in idx]
        time_unit = time_unit or HEADER_TIME_UNITS.get(units[0], "s")
        rate_unit = rate_unit or next(
            (HEADER_RATE_UNITS[u] for u in units[1:] if u in HEADER_RATE_UNITS), "rad/s"
        )
        if time_unit not in TIME_UNITS or rate_unit not in RATE_UNITS:
            raise GyroError(
                f"time unit must be one of {list(TIME_UNITS)}, rate unit one of {list(RATE_UNITS)}"
            )
        decimal_comma = delimiter != ","
        rows = []
        for number, row in enumerate(csv.reader(f, delimiter=delimiter), start=2):
            if not row or not "".join(row).strip():
                continue
            if len(row) != len(names):
                raise GyroError(f"{path}:{number}: expected {len(names)} fields, got {len(row)}")
            try:
                fields = [row[i].replace(",", ".") if decimal_comma else row[i] for i in idx]
                rows.append([float(v) for v in fields])
            except ValueError:
                raise GyroError(f"{path}:{number}: not a number") from None
    if not rows:
        raise GyroError(f"{path}: no gyro samples")
    data = np.array(rows)
    return GyroLog(
        data[:, 0] * TIME_UNITS[time_unit], data[:, 1:] * RATE_UNITS[rate_unit], str(path)
    )


def _wanted_columns(
    names: list[str],
    time_column: str | None = None,
    columns: tuple[str, str, str] | None = None,
) -> list[str]:
    """The time and x, y, z rate columns a CSV whose header names ``names`` is read by:
    those given, else Sensor Logger's, else the first of the usual names present."""
    if time_column is None:
        sensorlogger = {"seconds_elapsed", "x", "y", "z"} <= set(names)
        times = ("t", "time", "timestamp", "t_s")
        time_column = "seconds_elapsed" if sensorlogger else _pick(names, times)
    axes = columns or tuple(_pick(names, (a, f"g{a}", f"gyro_{a}", f"w{a}")) for a in "xyz")
    return [time_column.lower(), *(c.lower() for c in axes)]


def is_gyro_log(path: str | Path) -> bool:
    """Whether a file begins as a gyro log of one of the formats read here: a Gyroflow
    header, four numbers, or a CSV header naming a time column and x, y, z rate columns.
    A clip's notes of its name (``clip.txt``) do not, and ``--gyro auto`` leaves them be:
    it refused the clip ("no column named t, x, y, z")."""
    try:
        fmt = detect_format(path)
    except GyroError:
        return False
    if fmt != "csv":
        return True
    with open(path, newline="", encoding="utf-8-sig", errors="replace") as f:
        header = f.readline()
    names = [_column(n)[0] for n in next(csv.reader([header], delimiter=_delimiter(header)), [])]
    return set(_wanted_columns(names)) <= set(names)


def _pick(names: list[str], candidates: tuple[str, ...]) -> str:
    for c in candidates:
        if c in names:
            return c
    return candidates[0]


def read_telemetry(path: str | Path) -> GyroLog:
    """Gyro embedded in a camera's file (GoPro GPMF, Sony, Insta360, DJI, Google CAMM, ...),
    through the optional ``telemetry-parser`` package; times on the video's timeline."""
    path = Path(path)
    data = np.array(_telemetry_rows(path), dtype=np.float64)
    _, keep = np.unique(data[:, 0], return_index=True)  # repeated stamps at block joins
    data = data[np.sort(keep)]
    return GyroLog(data[:, 0] * 1e-3, np.radians(data[:, 1:]), str(path))


def _telemetry_rows(path: Path) -> list[tuple[float, ...]]:
    """(ms, gx, gy, gz in °/s) of each gyro sample a camera wrote into its file, or a
    GyroError saying why there are none."""
    try:
        import telemetry_parser
    except ImportError:
        raise GyroError(f"{path}: reading a camera's own gyro needs {TELEMETRY_EXTRA}") from None
    if not path.is_file():
        raise GyroError(f"{path}: no such file")
    try:
        samples = telemetry_parser.Parser(str(path)).normalized_imu()
    except Exception as err:  # the parser raises its own types
        raise GyroError(f"{path}: no readable camera telemetry ({err})") from None
    rows = [(s["timestamp_ms"], *s["gyro"]) for s in samples if s.get("gyro") is not None]
    if len(rows) < 2:
        raise GyroError(f"{path}: no gyro samples in the camera telemetry")
    return rows


def unread_telemetry() -> str:
    """What a message where no camera's own gyro was found adds where none could be read
    here (the telemetry extra is not installed): how to read one; else nothing."""
    if importlib.util.find_spec("telemetry_parser") is not None:
        return ""
    return f"; a camera's own is read with {TELEMETRY_EXTRA}"


def carries_gyro(path: str | Path) -> bool:
    """Whether a clip holds the gyro its camera recorded (a GoPro's GPMF track, ...), as
    :func:`read_telemetry` reads it; False without the telemetry extra. About 20 ms on
    each GoPro clip of ../shared (4 MB)."""
    try:
        _telemetry_rows(Path(path))
    except GyroError:
        return False
    return True


def detect_format(path: str | Path) -> str:
    """Guess the format from the suffix (camera files) or the first lines."""
    path = Path(path)
    if path.suffix.lower() in VIDEO_SUFFIXES:
        return "telemetry"
    _check_file(path)
    with open(path, errors="replace") as f:
        first = f.readline().strip()
    if not first:
        raise GyroError(f"{path}: no gyro samples (the file is empty)")
    if first.upper().startswith("GYROFLOW IMU LOG"):
        return "gcsv"
    fields = first.split(",")
    try:
        values = [float(v) for v in fields]
    except ValueError:
        return "csv"  # a header line: columns by name (Sensor Logger included)
    if len(values) == 4:
        # OpenCamera logs integer nanoseconds; phone-cc9 logs float seconds.
        return "opencamera" if fields[3].strip().lstrip("-").isdigit() else "phone-cc9"
    raise GyroError(f"{path}:1: unknown gyro log layout ({len(fields)} fields)")


# The registry: a format's name → its reader. Adding a format is a reader here, one line
# below, and a test.
READERS = {
    "opencamera": read_opencamera,
    "phone-cc9": read_phone_cc9,
    "gcsv": read_gcsv,
    "sensorlogger": read_named_csv,
    "csv": read_named_csv,
    "telemetry": read_telemetry,
}
FORMATS = tuple(READERS)


def read_gyro(path: str | Path, fmt: str | None = None, **options) -> GyroLog:
    """Read a gyro log, detecting its format unless ``fmt`` is given."""
    fmt = fmt or detect_format(path)
    if fmt not in READERS:
        raise GyroError(f"unknown gyro format {fmt!r}; choose from {', '.join(FORMATS)}")
    return READERS[fmt](path, **options)
