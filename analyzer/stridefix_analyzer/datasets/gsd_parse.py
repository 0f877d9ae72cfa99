"""Parsing of one GetSensorData logfile (IPIN competition Track 3 format) into its raw records.

The text side only: ``;``-separated records after ``%`` header lines (format in
the data set's README and in each file's header). :func:`parse_log` keeps, per record type,
the numbers the conversion (:mod:`.gsd_convert`) needs, in file order and on the file's own clocks;
nothing is aligned, grouped or projected here.

Bad data is not an error: a malformed line (wrong field count, a field that is not a number, a time
beyond ±10¹² s or an integer beyond its column's type, an unknown record tag) is counted, skipped and reported with a :class:`~.lines.MalformedLineWarning`
naming file and line. BLE4 records (iBeacon and Eddystone: app time, MAC, RSSI) are kept. Record types not
imported (AHRS, LIGH, SOUN, ...) are counted per type. A
missing or unreadable file raises :class:`LogReadError` naming it; a pressure unit the importer does
not know raises :class:`LogHeaderError`.

Cost: one pass over the text (~0.5 s per 10⁵ lines), memory ∝ the samples of one log.
"""

from __future__ import annotations

import dataclasses
import os
import re

from stridefix_analyzer.datasets.lines import LineReader
from stridefix_analyzer.datasets.protocol import DatasetReadError
from stridefix_analyzer.datasets.rawwalk import (
    INT16_RANGE,
    INT32_RANGE,
    bounded_int,
    bssid_to_int,
    finite,
    times_s,
)

#: Malformed lines reported one by one per file; the rest are summed up in one warning.
MAX_LINE_WARNINGS = 20

# record type -> number of ';'-separated fields, the tag included (WIFI: at least; an SSID may hold ';')
_FIELDS = {"ACCE": 7, "GYRO": 7, "MAGN": 7, "PRES": 5, "GNSS": 11, "WIFI": 7, "POSI": 7, "BLE4": 5}
#: BLE4 frame kinds (the header's two BLE4 formats); BLE4 has at least _FIELDS["BLE4"] fields
BLE4_KINDS = ("iBeacon", "Eddystone")
INERTIAL = ("ACCE", "GYRO", "MAGN")
_TAG_RE = re.compile(r"^[A-Z][A-Z0-9]{3}$")
_PRESSURE_TO_PA = {"mbar": 100.0, "hpa": 100.0, "pa": 1.0, "kpa": 1000.0}
_DEVICE_KEYS = ("Manufacturer", "Model", "API Android version", "Android version Release")


class LogReadError(DatasetReadError):
    """A logfile is missing or cannot be read. The message names the file."""


class LogHeaderError(LogReadError):
    """The logfile's header declares what the import cannot convert (e.g. an unknown pressure unit)."""


@dataclasses.dataclass
class GsdRecords:
    """The records of one logfile, in file order; times [s] as in the file.

    Attributes
    ----------
    inertial : per ACCE/GYRO/MAGN, rows (app time, sensor time, x, y, z)
    pres : rows (app time, sensor time, pressure in the header's unit)
    gnss : rows (app time, fix time, lat [deg], lon [deg], alt [m], accuracy [m])
    wifi : rows (app time, sensor time, bssid, rssi [dBm], freq [MHz])
    posi : rows (app time, lat [deg], lon [deg], floor id, building id)
    ble : rows (app time, MAC as 48-bit int, rssi [dBm]) of BLE4 (iBeacon and Eddystone)
    header : device lines of the ``%`` header (Manufacturer, Model, ...)
    pa_per_unit, pressure_unit : the header's pressure unit (None: no PRES format line; mbar assumed)
    """

    path: str
    inertial: dict[str, list[list[float]]]
    pres: list[list[float]]
    gnss: list[tuple[float, float, float, float, float, float]]
    wifi: list[tuple[float, float, int, float, int]]
    posi: list[tuple[float, float, float, int, str]]
    ble: list[tuple[float, int, float]]
    header: dict[str, str]
    pa_per_unit: float
    pressure_unit: str | None
    n_lines: int
    ignored: dict[str, int]
    skipped: list[tuple[int, str]]


def _header_units(header_lines: list[tuple[int, str]], path: str) -> tuple[float, str | None]:
    """Pressure scale to Pa from the header's ``'PRES;...;Pres(UNIT);...'``: (scale, unit)."""
    for line_no, text in header_lines:
        if "'PRES;" not in text:
            continue
        m = re.search(r"Pres\(([^)]*)\)", text)
        unit = m.group(1).strip() if m else ""
        if unit.lower() not in _PRESSURE_TO_PA:
            raise LogHeaderError(
                path, f"line {line_no}: pressure unit {unit!r} is not one of mbar, hPa, kPa, Pa"
            )
        return _PRESSURE_TO_PA[unit.lower()], unit
    return 100.0, None


def _latlon_ok(lat: float, lon: float) -> None:
    if not (-90 <= lat <= 90 and -180 <= lon <= 180):
        raise ValueError(f"latitude/longitude {lat}, {lon} out of range")


def parse_log(path: str | os.PathLike[str], max_line_warnings: int = MAX_LINE_WARNINGS) -> GsdRecords:
    """Read the records of one logfile (see the module docstring).

    Raises
    ------
    LogReadError
        The file is missing, not a file, or unreadable.
    LogHeaderError
        The header declares a pressure unit that cannot be converted to Pa.
    """
    reader = LineReader(path, LogReadError, max_line_warnings)
    inertial: dict[str, list[list[float]]] = {k: [] for k in INERTIAL}
    pres: list[list[float]] = []
    gnss: list[tuple[float, float, float, float, float, float]] = []
    wifi: list[tuple[float, float, int, float, int]] = []
    posi: list[tuple[float, float, float, int, str]] = []
    ble: list[tuple[float, int, float]] = []
    header_lines: list[tuple[int, str]] = []
    header: dict[str, str] = {}
    bad = reader.bad
    for line_no, line in reader.lines():
        if line.startswith("%"):
            header_lines.append((line_no, line))
            key, sep, value = line[1:].partition(":")
            if sep and key.strip() in _DEVICE_KEYS:
                header[key.strip()] = value.strip()
            continue
        parts = line.split(";")
        kind = parts[0]
        if kind not in _FIELDS:
            if _TAG_RE.match(kind) and len(parts) > 1:
                reader.ignore(kind)
            else:
                bad(line_no, f"unknown record type {kind[:40]!r}")
            continue
        n = _FIELDS[kind]
        if len(parts) > n and parts[-1] == "":
            parts.pop()  # a trailing ';' (the header writes WIFI and POSI so)
        if len(parts) != n and not (kind in ("WIFI", "BLE4") and len(parts) > n):
            bad(line_no, f"{kind} with {len(parts)} fields, expected {n}")
            continue
        try:
            # every time through times_s (bounded), every integer through bounded_int (its column's
            # type): an absurd number is a malformed line here, not an overflow in the conversion
            if kind in inertial:
                values = finite(parts[1:6])
                times_s(values[:2])
                inertial[kind].append(values)
            elif kind == "PRES":
                values = finite(parts[1:4])
                times_s(values[:2])
                pres.append(values)
            elif kind == "GNSS":
                app, sensor, lat, lon, alt = finite(parts[1:6])
                times_s([app, sensor])
                acc = finite(parts[7:8])[0]
                _latlon_ok(lat, lon)
                gnss.append((app, sensor, lat, lon, alt, acc))
            elif kind == "WIFI":
                app, sensor = times_s(finite(parts[1:3]))
                freq = bounded_int(parts[-2], INT32_RANGE, "frequency [MHz]")
                wifi.append((app, sensor, bssid_to_int(parts[-3].strip()), finite(parts[-1:])[0], freq))
            elif kind == "BLE4":
                if parts[2] not in BLE4_KINDS:
                    raise ValueError(f"frame kind {parts[2][:20]!r} not one of {BLE4_KINDS}")
                app = times_s(finite(parts[1:2]))[0]
                ble.append((app, bssid_to_int(parts[3].strip()), finite(parts[4:5])[0]))
            else:  # POSI
                app, lat, lon = finite([parts[1], parts[3], parts[4]])
                times_s([app])
                _latlon_ok(lat, lon)
                floor = bounded_int(parts[5], INT16_RANGE, "floor")  # truth_t.floor
                posi.append((app, lat, lon, floor, parts[6].strip()))
        except ValueError as exc:
            bad(line_no, f"{kind}: {exc}")
    reader.finish()
    pa_per_unit, unit = _header_units(header_lines, reader.path)
    return GsdRecords(
        path=reader.path,
        inertial=inertial,
        pres=pres,
        gnss=gnss,
        wifi=wifi,
        posi=posi,
        ble=ble,
        header=header,
        pa_per_unit=pa_per_unit,
        pressure_unit=unit,
        n_lines=reader.n_lines,
        ignored=reader.ignored,
        skipped=reader.skipped,
    )
