"""Reading the gyro log a job names, and checking it, before any work: reading it costs
no numba kernel, so a bad log is reported in a fraction of a second. ``--gyro auto``
finds the log: beside the clip, else in it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from stabilize.gyro.log import GyroError, GyroLog
from stabilize.gyro.readers import (
    GYRO_SIDECARS,
    carries_gyro,
    is_gyro_log,
    read_gyro,
    unread_telemetry,
)
from stabilize.settings import Settings

# --gyro auto looks beside a clip for a log of its name: an image sequence has none
AUTO_FOR_SEQUENCE = "--gyro auto finds a clip's own log; an image sequence's is given: --gyro LOG"


def load_gyro(settings: Settings) -> GyroLog:
    """The log ``settings`` name, read, checked and filtered before any work is done."""
    log = read_gyro(settings.gyro, settings.gyro_format)
    if settings.readout_ms is not None:
        readout_seconds(settings.readout_ms)
    return lowpass(log, settings.gyro_lpf) if settings.gyro_lpf else log


def lowpass(log: GyroLog, cutoff_hz: float) -> GyroLog:
    """Zero-phase 2nd-order Butterworth low-pass of the rates (no lag)."""
    nyquist = 0.5 * log.rate_hz
    if not 0 < cutoff_hz < nyquist:
        raise GyroError(f"--gyro-lpf must be between 0 and {nyquist:.0f} Hz, got {cutoff_hz}")
    from scipy.signal import butter, filtfilt  # about 1 s to import: only when filtering

    b, a = butter(2, cutoff_hz, fs=log.rate_hz)
    return replace(log, rates=filtfilt(b, a, log.rates, axis=0))


def readout_seconds(option: float | str) -> float | None:
    """``--readout-ms``: a number of ms, in s, or 'auto' (None: estimate it)."""
    if option == "auto":
        return None
    value = float(option)
    if not 0.0 <= value < 1000.0:
        raise ValueError(f"--readout-ms must be between 0 and 1000 ms, got {option}")
    return value / 1000.0


def starting_readout(
    option: float | str | None, from_log: float | None, from_lens: float | None
) -> tuple[float | None, str]:
    """The readout a gyro path starts from (s; None: estimate it) and its source:
    ``--readout-ms`` as ``given`` ('auto': ``estimated``), else the ``log``'s own value,
    else the ``lens`` profile's, else ``estimated``: a log that gives none (phone-cc9's,
    a GoPro's) no longer means a global shutter. phone-cc9 from its gyro at 0 read 1.181 px
    of residual shake and 1.369 of wobble; at the 23.4 ms found against the gyro, 1.082
    and 1.224."""
    if option is not None:
        return readout_seconds(option), "estimated" if option == "auto" else "given"
    for value, source in ((from_log, "log"), (from_lens, "lens")):
        if value is not None:
            return float(value), source
    return None, "estimated"


def find_gyro_log(clip: str | Path) -> Path | None:
    """``--gyro auto``'s log for ``clip``: one beside it of the same name (the first of
    :data:`GYRO_SIDECARS` that is a ``.gcsv`` or begins as a gyro log: not the clip's
    notes, :func:`is_gyro_log`), else the clip itself where its camera recorded its gyro
    in it (:func:`carries_gyro`); None where there is neither."""
    clip = Path(clip)
    found = next((path for path in _beside(clip) if _taken(path)), None)
    return found or (clip if carries_gyro(clip) else None)


def _beside(clip: Path) -> list[Path]:
    """The files beside ``clip`` of its name that a gyro log of it would be."""
    return [path for s in GYRO_SIDECARS if (path := clip.with_suffix(s)).is_file()]


def _taken(path: Path) -> bool:
    # a .gcsv is a log by its name: one that does not read is refused, not passed over
    return path.suffix.lower() == ".gcsv" or is_gyro_log(path)


def gyro_log_for(clip: str | Path) -> Path:
    """:func:`find_gyro_log`'s log for ``clip``, or a GyroError where it has none."""
    found = find_gyro_log(clip)
    if found is None:
        sidecars = ", ".join(GYRO_SIDECARS)
        others = [path.name for path in _beside(Path(clip))]
        passed = f" ({', '.join(others)} beside it: no gyro log)" if others else ""
        raise GyroError(
            f"--gyro auto: no gyro log beside {clip} ({sidecars}){passed}, nor in it"
            f"{unread_telemetry()}"
        )
    return found


def gyro_settings(log: Path, clip: Path) -> dict:
    """The Settings fields of ``--gyro auto``'s ``log`` for ``clip``: a camera's own
    gyro (the clip itself) is read as its telemetry, whatever ``--gyro-format`` names
    for the logs beside clips, and gives way to the video's motion where it does not
    match it (a clip the camera steadied: a GoPro's HyperSmooth)."""
    own = log == clip
    return {"gyro": str(log), "gyro_fallback": own} | ({"gyro_format": "telemetry"} if own else {})
