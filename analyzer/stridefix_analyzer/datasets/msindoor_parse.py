"""Parsing of one Microsoft Indoor Location Competition 2.0 trace into a :class:`~.rawwalk.RawWalk`.

The file format is in the data set's own README (docs/datasets.md): tab-separated ``unix-ms  TYPE_...  values``
lines after ``#`` header lines. What becomes of each record (:mod:`.msindoor` has the table):

* TYPE_ACCELEROMETER → ``imu`` (m/s²), with TYPE_GYROSCOPE (rad/s) interpolated linearly to the
  accelerometer times (held at the end values outside the gyroscope's span); the ``*_UNCALIBRATED``
  variants are counted, not used. TYPE_MAGNETIC_FIELD → ``mag`` (µT).
* TYPE_WIFI lines sharing a first-column time are one scan; an entry whose last_seen time is more than
  ``max_wifi_age_s`` older than the scan is a cached result, dropped; a BSSID heard twice keeps its
  freshest entry; a scan left empty is counted, not kept.
* TYPE_BEACON → ``ble``: the MAC is the beacon id, the RSSI [dBm] the reading; like Wi-Fi lines the
  first column is system time, used as is (as the Wi-Fi scans are), and readings group into windows
  of :data:`~.rawwalk.BLE_WINDOW_S` (:func:`~.rawwalk.ble_scans`; the format has no scan grouping).
* TYPE_WAYPOINT → ``truth`` on the floor of the FloorName header (F1 → 0, F2 → 1, B1 → −1, ...).

Times: ``t_us`` = the file's unix time [ms] × 1000. Bad data is not an error: a malformed line (a
time beyond 10¹² s, a frequency beyond an int32 among them: :mod:`.rawwalk`'s bounds) is counted,
skipped and warned about (:class:`~.lines.MalformedLineWarning`, naming file and line).
Cost: one pass over the text (~1 s per 10⁵ lines), memory ∝ the samples of one trace.
"""

from __future__ import annotations

import os
import re

import numpy as np

from stridefix_analyzer.datasets.lines import LineReader
from stridefix_analyzer.datasets.protocol import DEFAULT_MAX_WIFI_AGE_S, DatasetReadError, check_has_records
from stridefix_analyzer.datasets.rawwalk import (
    INT16_RANGE,
    INT32_RANGE,
    RawWalk,
    ble_scans,
    bounded_int,
    bssid_to_int,
    dedupe_sorted,
    finite,
    gyro_at,
    unix_ms,
    wifi_scans,
)
from stridefix_analyzer.io.logread import Table

#: Malformed lines reported one by one per file; the rest are summed up in one warning.
MAX_LINE_WARNINGS = 20

_SENSOR_TYPES = {"TYPE_ACCELEROMETER": "accel", "TYPE_GYROSCOPE": "gyro", "TYPE_MAGNETIC_FIELD": "mag"}
# record type -> number of tab-separated fields, time and type included
_FIELDS = {
    "TYPE_ACCELEROMETER": 6,
    "TYPE_GYROSCOPE": 6,
    "TYPE_MAGNETIC_FIELD": 6,
    "TYPE_WIFI": 7,
    "TYPE_WAYPOINT": 4,
    "TYPE_BEACON": 10,
}


class TraceReadError(DatasetReadError):
    """A trace file is missing or cannot be read. The message names the file."""


class TraceHeaderError(TraceReadError):
    """The trace's header lacks what the import needs (e.g. an unknown FloorName)."""


def floor_index(name: str) -> int:
    """Floor index of a FloorName: ``F1``/``1F``/``L1``/``G`` → 0, ``F2`` → 1, ``B1``/``1B`` → −1.

    Raises
    ------
    ValueError
        The name follows none of these patterns, or its index is beyond an int16 (``truth_t.floor``).
    """
    s = name.strip().upper()
    if s in ("G", "GF"):
        return 0
    above = re.fullmatch(r"(?:F|L)([0-9]+)|([0-9]+)F", s)
    below = re.fullmatch(r"B([0-9]+)|([0-9]+)B", s)
    m = above or below
    digits = ((m.group(1) or m.group(2)) if m else "").lstrip("0")
    if not digits:  # no match, or floor 0
        raise ValueError(f"floor name {name[:40]!r} is not F<n>, <n>F, L<n>, G, B<n> or <n>B")
    # truth_t.floor is an int16: a longer number is refused before int() reads all its digits
    lo, hi = INT16_RANGE
    index = (int(digits) - 1 if above else -int(digits)) if len(digits) <= 6 else hi + 1
    if not lo <= index <= hi:
        raise ValueError(f"floor name {name[:40]!r}: floor index outside {lo}..{hi}")
    return index


def _columns(rows: list[tuple[float, ...]], width: int) -> tuple[np.ndarray, np.ndarray]:
    """(time [ms] int64, values (n, width)) of (t_ms, v...) rows."""
    if not rows:
        return np.zeros(0, dtype=np.int64), np.zeros((0, width))
    a = np.asarray(rows, dtype=np.float64)
    return a[:, 0].astype(np.int64), a[:, 1:]


def read_trace(
    path: str | os.PathLike[str],
    max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S,
    floor: int | None = None,
    max_line_warnings: int = MAX_LINE_WARNINGS,
) -> RawWalk:
    """Parse one trace file.

    Parameters
    ----------
    path : the trace (tab-separated text)
    max_wifi_age_s : Wi-Fi entries with scan time − last_seen time above this [s] are dropped
    floor : floor index of the waypoints; default: from the FloorName header
    max_line_warnings : malformed lines warned about one by one; further ones are summed up

    Returns
    -------
    RawWalk
        ``meta``: ``header`` (the ``key:value`` pairs of the ``#`` lines), ``floor_name``, ``floor``.

    Raises
    ------
    TraceReadError
        The file is missing, not a file, or unreadable.
    TraceHeaderError
        No usable FloorName header and ``floor`` not given (a file without one sensor record raises
        :class:`~.protocol.NothingValidError` instead: that is the first thing wrong with it).
    """
    reader = LineReader(path, TraceReadError, max_line_warnings)
    name = reader.path
    samples: dict[str, list[tuple[float, ...]]] = {"accel": [], "gyro": [], "mag": []}
    wifi: dict[int, list[tuple[int, float, int, float]]] = {}
    waypoints: list[tuple[float, ...]] = []
    beacons: list[tuple[int, int, float]] = []
    header: dict[str, str] = {}
    bad = reader.bad
    for line_no, line in reader.lines():
        if line.startswith("#"):
            for token in line[1:].split("\t"):
                key, sep, value = token.strip().partition(":")
                if sep:
                    header[key] = value
            continue
        parts = line.split("\t")
        if line.count("\tTYPE_") > 1:
            bad(line_no, f"{line.count(chr(9) + 'TYPE_')} records run together")
            continue
        if len(parts) < 2 or not (parts[0].isascii() and parts[0].isdigit()):
            bad(line_no, "no unix-ms time in the first field")
            continue
        kind = parts[1]
        if kind not in _FIELDS:
            if kind.startswith("TYPE_"):
                reader.ignore(kind)
            else:
                bad(line_no, f"unknown record type {kind[:40]!r}")
            continue
        if len(parts) != _FIELDS[kind]:
            bad(line_no, f"{kind} with {len(parts)} fields, expected {_FIELDS[kind]}")
            continue
        try:
            t_ms = unix_ms(parts[0])
            if kind == "TYPE_WIFI":
                bssid, rssi, freq, seen = (
                    bssid_to_int(parts[3]),
                    finite(parts[4:5])[0],
                    bounded_int(parts[5], INT32_RANGE, "frequency [MHz]"),
                    unix_ms(parts[6].strip()),
                )
                wifi.setdefault(t_ms, []).append((bssid, rssi, freq, float(t_ms - seen)))
            elif kind == "TYPE_BEACON":
                beacons.append((t_ms * 1000, bssid_to_int(parts[8]), finite(parts[6:7])[0]))
            elif kind == "TYPE_WAYPOINT":
                waypoints.append((t_ms, *finite(parts[2:4])))
            else:
                # finite() written out for the ~95 % of lines that are sensor samples: the same
                # conversions in the same order, so the same first error; x − x is 0.0 (false) only
                # for a finite x (NaN and ±inf give NaN, which is true)
                x, y, z = float(parts[2]), float(parts[3]), float(parts[4])
                if (x - x) or (y - y) or (z - z):
                    raise ValueError("non-finite value")
                samples[_SENSOR_TYPES[kind]].append((t_ms, x, y, z))
        except ValueError as exc:
            bad(line_no, f"{kind}: {exc}")
    reader.finish()

    floor_name = header.get("FloorName", "")
    floor_error = None
    if floor is None:
        try:
            floor = floor_index(floor_name)
        except ValueError as exc:
            floor_error, floor = f"no floor index: {exc} (pass the floor explicitly)", 0
    notes: list[str] = []
    stats: dict[str, object] = {
        "lines": reader.n_lines,
        "ignored_lines_by_type": dict(sorted(reader.ignored.items())),
    }
    acc_t, acc, dup_a = dedupe_sorted(*_columns(samples["accel"], 3))
    gyr_t, gyr, dup_g = dedupe_sorted(*_columns(samples["gyro"], 3))
    mag_t, mag, dup_m = dedupe_sorted(*_columns(samples["mag"], 3))
    stats["duplicate_times_dropped"] = {"accel": dup_a, "gyro": dup_g, "mag": dup_m}
    gyro, held = gyro_at(acc_t, gyr_t, gyr, notes, "TYPE_GYROSCOPE line")
    stats["imu_gyro_held"] = held
    if not len(acc_t):
        notes.append("no TYPE_ACCELEROMETER line: no IMU message")

    scans = wifi_scans([(t_ms * 1000, wifi[t_ms]) for t_ms in sorted(wifi)], max_wifi_age_s, stats)
    ble = ble_scans(beacons, stats)

    waypoints.sort(key=lambda w: w[0])
    wp_t = np.array([w[0] for w in waypoints], dtype=np.int64)
    wp_xy = np.array([w[1:] for w in waypoints], dtype=np.float64).reshape(-1, 2)
    raw = RawWalk(
        path=name,
        imu=Table({"t_us": acc_t * 1000, "accel_mps2": acc, "gyro_radps": gyro}),
        mag=Table({"t_us": mag_t * 1000, "field_ut": mag}),
        wifi=scans,
        ble=ble,
        truth=Table(
            {
                "t_us": wp_t * 1000,
                "x_m": wp_xy[:, 0],
                "y_m": wp_xy[:, 1],
                "floor": np.full(len(wp_t), int(floor), dtype=np.int64),
            }
        ),
        meta={"header": header, "floor_name": floor_name, "floor": int(floor)},
        stats=stats,
        skipped=reader.skipped,
        notes=notes,
    )
    if floor_error is not None:
        check_has_records(raw)  # a file without one sensor record is that first (empty, PNG, UTF-16)
        raise TraceHeaderError(name, floor_error)
    return raw
