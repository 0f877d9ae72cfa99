"""Importer of GetSensorData logfiles (the IPIN competition Track 3 format: real Android phone walks).

One logfile (``../shared/data/gsd/*.txt``; format in that folder's README and in each file's ``%``
header) becomes one raw-sensor LCM event log that ``stridefixd --input lcmlog:FILE`` replays:

=======  ===========  =====================================================================================
channel  type         from
=======  ===========  =====================================================================================
IMU      imu_t        ``ACCE`` (m/s²), with ``GYRO`` (rad/s) linearly interpolated to the accelerometer
                      times (held at the end values outside the gyroscope's time span); seq = 0, 1, ...
MAG      mag_t        ``MAGN`` (µT)
BARO     baro_t       ``PRES``, converted to Pa from the unit the header declares (mbar/hPa ×100, kPa
                      ×1000, Pa); temperature NaN (the logs carry none with the pressure)
GNSS     gnss_t       ``GNSS``: latitude, longitude, altitude, accuracy; the app logs most fixes twice
                      (same fix time = SensorTimestamp): the repeats are dropped (counted)
WIFI     wifi_scan_t  one scan = the ``WIFI`` records whose AppTimestamps lie within
                      :data:`WIFI_GROUP_S` of the scan's first one; BSSID ``aa:bb:..:ff`` → 0xaabb..ff;
                      frequency from the file; an entry last seen (its SensorTimestamp, on the inertial
                      clock base below) more than ``max_wifi_age_s`` before the scan is a cached result
                      and dropped; a BSSID heard twice in one scan keeps its freshest entry
TRUTH    truth_t      ``POSI``: latitude/longitude → local metres, x east and y north, by a local tangent
                      plane about an origin (:func:`project`); floor = the floor id; heading NaN,
                      step_count −1, source SOURCE_WAYPOINT. The building id goes into the summary.
=======  ===========  =====================================================================================

Times: ``t_us`` = AppTimestamp [s] × 10⁶ (the common clock of all records), except the inertial
samples (ACCE, GYRO and MAGN, one sensor clock): those are timed by their SensorTimestamps,
``t = SensorTimestamp + offset``, one constant offset for the file = the median of AppTimestamp −
SensorTimestamp over the inertial samples of the first :data:`CLOCK_ALIGN_S` seconds (the first few
samples arrive 40–75 ms late, so the first pair alone is a poor anchor). So the inertial time steps are
the sensor's own and the streams still share the clock of Wi-Fi, GNSS and the truth. Everything is
imported, the calibration minute included; TRUTH starts at the first POSI. The LCM event timestamp is
``t_us`` and events are written in time order (ties: IMU, MAG, BARO, GNSS, WIFI, TRUTH).

Bad data is not an error: a malformed line (wrong field count, a field that is not a number, an
unknown record tag) is counted, skipped and reported with a :class:`MalformedLineWarning` naming file
and line. Record types not imported (AHRS, LIGH, SOUN, BLE4, ...) are counted per type. A missing or
unreadable file raises :class:`LogReadError` naming it; a pressure unit the importer does not know
raises :class:`LogHeaderError`.

Cost: one pass over the text (~0.5 s per 10⁵ lines), memory ∝ the samples of one log.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from pathlib import Path

import numpy as np

from stridefix_analyzer.datasets.lines import LineReader, MalformedLineWarning
from stridefix_analyzer.datasets.msindoor import DEFAULT_MAX_WIFI_AGE_S, _dedupe_sorted, bssid_to_int

__all__ = [
    "GsdLog",
    "LogReadError",
    "LogHeaderError",
    "MalformedLineWarning",
    "read_log",
    "write_lcmlog",
    "import_log",
    "import_trace",
    "project",
    "parse_origin",
]

#: Bump when the log content for the same input changes (caches compare it).
IMPORTER_VERSION = 1
#: Malformed lines reported one by one per file; the rest are summed up in one warning.
MAX_LINE_WARNINGS = 20
#: WIFI records whose AppTimestamps lie within this of a scan's first record belong to that scan [s].
WIFI_GROUP_S = 0.010
#: The sensor → app clock offset is the median over the inertial samples of the first S seconds.
CLOCK_ALIGN_S = 10.0
#: WGS-84 semi-major axis [m] and first eccentricity squared.
WGS84_A = 6378137.0
WGS84_E2 = 6.69437999014e-3

CHANNELS = ("IMU", "MAG", "BARO", "GNSS", "WIFI", "TRUTH")  # also the tie-break order of equal times

# record type -> number of ';'-separated fields, the tag included (WIFI: at least; an SSID may hold ';')
_FIELDS = {"ACCE": 7, "GYRO": 7, "MAGN": 7, "PRES": 5, "GNSS": 11, "WIFI": 7, "POSI": 7}
_INERTIAL = ("ACCE", "GYRO", "MAGN")
_TAG_RE = re.compile(r"^[A-Z][A-Z0-9]{3}$")
_PRESSURE_TO_PA = {"mbar": 100.0, "hpa": 100.0, "pa": 1.0, "kpa": 1000.0}


class LogReadError(Exception):
    """A logfile is missing or cannot be read. The message names the file."""

    def __init__(self, path, reason: str):
        super().__init__(f"{path}: {reason}")
        self.path = str(path)
        self.reason = reason


class LogHeaderError(LogReadError):
    """The logfile's header declares what the import cannot convert (e.g. an unknown pressure unit)."""


def project(lat_deg, lon_deg, origin_lat_deg: float, origin_lon_deg: float) -> tuple:
    """Latitude/longitude [deg] → local metres (x east, y north) about the origin.

    A local tangent plane with the WGS-84 radii of curvature at the origin's latitude φ0:
    ``x = N(φ0)·cos φ0·(λ − λ0)``, ``y = M(φ0)·(φ − φ0)`` (angles in radians), with the
    prime-vertical radius ``N = a / sqrt(1 − e²·sin²φ0)`` and the meridian radius
    ``M = a·(1 − e²) / (1 − e²·sin²φ0)^1.5``.
    Over a building (< 1 km) it differs from a full ENU conversion by millimetres.
    """
    phi0 = math.radians(origin_lat_deg)
    w = 1.0 - WGS84_E2 * math.sin(phi0) ** 2
    n = WGS84_A / math.sqrt(w)
    m = WGS84_A * (1.0 - WGS84_E2) / w**1.5
    lat = np.asarray(lat_deg, dtype=np.float64)
    lon = np.asarray(lon_deg, dtype=np.float64)
    x = n * math.cos(phi0) * np.radians(lon - origin_lon_deg)
    y = m * np.radians(lat - origin_lat_deg)
    return x, y


def parse_origin(text: str) -> tuple[float, float]:
    """``"LAT,LON"`` [deg] → (lat, lon). Raises ValueError on another form or out-of-range values."""
    parts = text.replace(" ", "").split(",")
    if len(parts) != 2:
        raise ValueError(f"origin {text!r} is not LAT,LON")
    lat, lon = (float(p) for p in parts)
    if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0):
        raise ValueError(f"origin {text!r} out of range (latitude ±90, longitude ±180)")
    return lat, lon


@dataclasses.dataclass
class WifiScan:
    """One scan as written: time [µs]; per AP (n,) bssid, rssi_dbm, freq_mhz, age_ms (NaN: unknown)."""

    t_us: int
    bssid: np.ndarray
    rssi_dbm: np.ndarray
    freq_mhz: np.ndarray
    age_ms: np.ndarray


@dataclasses.dataclass
class GsdLog:
    """One parsed logfile, in time order, ready to write. Times are µs (int64).

    Attributes
    ----------
    imu_t_us : (n,) strictly increasing accelerometer times; accel_mps2, gyro_radps : (n, 3)
    mag_t_us : (m,); mag_ut : (m, 3) [µT]
    baro_t_us : (b,); baro_pa : (b,) [Pa]
    gnss_t_us : (g,); gnss : (g, 4) latitude [deg], longitude [deg], altitude [m], accuracy [m]
    scans : list of WifiScan (non-empty scans only)
    truth_t_us : (w,); truth_xy_m : (w, 2); truth_floor : (w,) int; truth_latlon : (w, 2) [deg]
    building_ids : list of str, the distinct POSI building ids in file order
    origin : (lat, lon) [deg] of the projection, or None (no POSI and none given)
    origin_source : "option" or "first POSI"
    header : dict, device lines of the ``%`` header (Manufacturer, Model, ...)
    stats : dict, counts reported by :meth:`summary`; skipped : list of (line number, reason)
    """

    path: str
    header: dict
    imu_t_us: np.ndarray
    accel_mps2: np.ndarray
    gyro_radps: np.ndarray
    mag_t_us: np.ndarray
    mag_ut: np.ndarray
    baro_t_us: np.ndarray
    baro_pa: np.ndarray
    gnss_t_us: np.ndarray
    gnss: np.ndarray
    scans: list
    truth_t_us: np.ndarray
    truth_xy_m: np.ndarray
    truth_floor: np.ndarray
    truth_latlon: np.ndarray
    building_ids: list
    origin: tuple | None
    origin_source: str | None
    stats: dict
    skipped: list
    notes: list

    def time_span_us(self) -> tuple[int, int] | None:
        """(first, last) time of anything written [µs], or None for an empty log."""
        ts = [
            a
            for a in (self.imu_t_us, self.mag_t_us, self.baro_t_us, self.gnss_t_us, self.truth_t_us)
            if len(a)
        ]
        ts += [np.array([s.t_us for s in self.scans])] if self.scans else []
        if not ts:
            return None
        return int(min(a.min() for a in ts)), int(max(a.max() for a in ts))

    def summary(self) -> dict:
        """Counts per channel, rates, origin, building, skipped lines: a JSON-ready dict."""
        span = self.time_span_us()

        def rate(t):
            dt = np.diff(t)
            return float(1e6 / np.median(dt)) if len(dt) else None

        dt = np.diff(self.imu_t_us)
        floors = sorted(set(self.truth_floor.tolist()))
        return {
            "trace": self.path,
            "format": "gsd",
            "device": dict(self.header),
            "building_id": self.building_ids[0] if len(self.building_ids) == 1 else None,
            "building_ids": list(self.building_ids),
            "floors": floors,
            "floor": floors[0] if len(floors) == 1 else None,
            "origin": None
            if self.origin is None
            else {"lat_deg": self.origin[0], "lon_deg": self.origin[1], "source": self.origin_source},
            "projection": "local tangent plane, WGS-84 radii at the origin; x east, y north [m]",
            "messages": {
                "IMU": len(self.imu_t_us),
                "MAG": len(self.mag_t_us),
                "BARO": len(self.baro_t_us),
                "GNSS": len(self.gnss_t_us),
                "WIFI": len(self.scans),
                "TRUTH": len(self.truth_t_us),
            },
            "waypoints": len(self.truth_t_us),
            "t_start_us": None if span is None else span[0],
            "t_end_us": None if span is None else span[1],
            "duration_s": 0.0 if span is None else (span[1] - span[0]) / 1e6,
            "truth_t_first_us": int(self.truth_t_us[0]) if len(self.truth_t_us) else None,
            "truth_t_last_us": int(self.truth_t_us[-1]) if len(self.truth_t_us) else None,
            "imu_t_first_us": int(self.imu_t_us[0]) if len(self.imu_t_us) else None,
            "imu_t_last_us": int(self.imu_t_us[-1]) if len(self.imu_t_us) else None,
            "imu_rate_hz": rate(self.imu_t_us),
            "imu_max_gap_ms": float(dt.max()) / 1e3 if len(dt) else None,
            "mag_rate_hz": rate(self.mag_t_us),
            "baro_rate_hz": rate(self.baro_t_us),
            "skipped_lines": len(self.skipped),
            "skipped": [{"line": n, "reason": r} for n, r in self.skipped[:100]],
            **self.stats,
            "notes": list(self.notes),
        }


def _finite(values: list[str]) -> list[float]:
    out = [float(x) for x in values]
    if not all(math.isfinite(x) for x in out):
        raise ValueError("non-finite value")
    return out


def _header_units(header_lines: list[tuple[int, str]], path: str) -> tuple[float, str | None, int]:
    """Pressure scale to Pa from the header's ``'PRES;...;Pres(UNIT);...'``: (scale, unit, line)."""
    for line_no, text in header_lines:
        if "'PRES;" not in text:
            continue
        m = re.search(r"Pres\(([^)]*)\)", text)
        unit = m.group(1).strip() if m else ""
        if unit.lower() not in _PRESSURE_TO_PA:
            raise LogHeaderError(
                path, f"line {line_no}: pressure unit {unit!r} is not one of mbar, hPa, kPa, Pa"
            )
        return _PRESSURE_TO_PA[unit.lower()], unit, line_no
    return 100.0, None, 0


def read_log(
    path,
    origin: tuple[float, float] | None = None,
    max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S,
    max_line_warnings: int = MAX_LINE_WARNINGS,
) -> GsdLog:
    """Parse one GetSensorData logfile.

    Parameters
    ----------
    path : str or path
        The logfile (``;``-separated text with a ``%`` header).
    origin : (lat, lon) [deg], optional
        Origin of the local metres of the truth; default: the file's first POSI record. Pass one
        origin for every walk of a building to put them in one frame.
    max_wifi_age_s : float
        Wi-Fi entries last seen more than this before their scan [s] are cached results, dropped.
    max_line_warnings : int
        Malformed lines warned about one by one; further ones are summed up in one warning.

    Raises
    ------
    LogReadError
        The file is missing, not a file, or unreadable.
    LogHeaderError
        The header declares a pressure unit that cannot be converted to Pa.
    """
    reader = LineReader(path, LogReadError, max_line_warnings)
    path = reader.path
    inertial = {k: [] for k in _INERTIAL}  # (app, sensor, x, y, z)
    pres, gnss, wifi, posi = [], [], [], []
    header_lines: list[tuple[int, str]] = []
    header: dict[str, str] = {}
    bad = reader.bad
    for line_no, line in reader.lines():
        if line.startswith("%"):
            header_lines.append((line_no, line))
            key, sep, value = line[1:].partition(":")
            if sep and key.strip() in (
                "Manufacturer",
                "Model",
                "API Android version",
                "Android version Release",
            ):
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
        if len(parts) != n and not (kind == "WIFI" and len(parts) > n):
            bad(line_no, f"{kind} with {len(parts)} fields, expected {n}")
            continue
        try:
            if kind in inertial:
                inertial[kind].append(_finite(parts[1:6]))
            elif kind == "PRES":
                pres.append(_finite(parts[1:4]))
            elif kind == "GNSS":
                app, sensor, lat, lon, alt = _finite(parts[1:6])
                acc = _finite(parts[7:8])[0]
                if not (-90 <= lat <= 90 and -180 <= lon <= 180):
                    raise ValueError(f"latitude/longitude {lat}, {lon} out of range")
                gnss.append((app, sensor, lat, lon, alt, acc))
            elif kind == "WIFI":
                app, sensor = _finite(parts[1:3])
                wifi.append(
                    (app, sensor, bssid_to_int(parts[-3].strip()), _finite(parts[-1:])[0], int(parts[-2]))
                )
            else:  # POSI
                app, lat, lon = _finite([parts[1], parts[3], parts[4]])
                if not (-90 <= lat <= 90 and -180 <= lon <= 180):
                    raise ValueError(f"latitude/longitude {lat}, {lon} out of range")
                posi.append((app, lat, lon, int(parts[5]), parts[6].strip()))
        except ValueError as exc:
            bad(line_no, f"{kind}: {exc}")
    reader.finish()
    skipped, ignored, n_lines = reader.skipped, reader.ignored, reader.n_lines

    notes: list[str] = []
    pa_per_unit, unit, _ = _header_units(header_lines, path)
    if unit is None and pres:
        notes.append("no PRES format line in the header: pressure taken as mbar")
    stats: dict = {
        "lines": n_lines,
        "ignored_lines_by_type": dict(sorted(ignored.items())),
        "pressure_unit": unit or "mbar (assumed)",
    }

    # --- inertial samples on their sensor clock, aligned to the app clock at the start
    arrays = {k: np.asarray(v, dtype=np.float64).reshape(-1, 5) for k, v in inertial.items()}
    offset, per_type = None, {}
    for k, a in arrays.items():
        if len(a):
            start = a[a[:, 0] <= a[:, 0].min() + CLOCK_ALIGN_S]
            per_type[k] = float(np.median(start[:, 0] - start[:, 1]))
    base = [k for k in ("ACCE", "GYRO") if k in per_type] or list(per_type)
    if base:
        a = np.concatenate([arrays[k] for k in base])
        start = a[a[:, 0] <= a[:, 0].min() + CLOCK_ALIGN_S]
        offset = float(np.median(start[:, 0] - start[:, 1]))
    offsets = {}
    for k, off in per_type.items():
        if abs(off - offset) > 1.0:  # a sensor on another clock: align it on its own
            notes.append(
                f"{k} SensorTimestamps are {off - offset:+.3f} s off the inertial clock: aligned separately"
            )
            offsets[k] = off
        else:
            offsets[k] = offset
    stats["clock_offset_s"] = offset  # app time = sensor time + offset
    stats["clock_align_s"] = CLOCK_ALIGN_S

    def sensor_times(k: str) -> tuple[np.ndarray, np.ndarray]:
        a = arrays[k]
        if not len(a):
            return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
        return np.round((a[:, 1] + offsets[k]) * 1e6).astype(np.int64), a[:, 2:5]

    acc_t, acc = sensor_times("ACCE")
    gyr_t, gyr = sensor_times("GYRO")
    mag_t, mag = sensor_times("MAGN")
    acc_t, acc, dup_a = _dedupe_sorted(acc_t, acc)
    gyr_t, gyr, dup_g = _dedupe_sorted(gyr_t, gyr)
    mag_t, mag, dup_m = _dedupe_sorted(mag_t, mag)
    if len(gyr_t):
        gyro = np.column_stack([np.interp(acc_t, gyr_t, gyr[:, i]) for i in range(3)])
        held = int(((acc_t < gyr_t[0]) | (acc_t > gyr_t[-1])).sum())
    else:
        gyro, held = np.zeros_like(acc), len(acc_t)
        if len(acc_t):
            notes.append("no GYRO record: gyro written as 0")
    if not len(acc_t):
        notes.append("no ACCE record: no IMU message")
    stats["imu_gyro_held"] = held
    stats["gyro_samples"] = len(gyr_t)
    stats["gyro_rate_hz"] = float(1e6 / np.median(np.diff(gyr_t))) if len(gyr_t) > 1 else None

    # --- barometer and GNSS on the app clock
    p = np.asarray(pres, dtype=np.float64).reshape(-1, 3)
    baro_t, baro, dup_p = _dedupe_sorted(np.round(p[:, 0] * 1e6).astype(np.int64), p[:, 2] * pa_per_unit)
    stats["duplicate_times_dropped"] = {"ACCE": dup_a, "GYRO": dup_g, "MAGN": dup_m, "PRES": dup_p}

    gnss.sort(key=lambda r: r[0])
    kept, repeats, last_fix = [], 0, None
    for app, sensor, lat, lon, alt, acc_m in gnss:
        fix = (sensor, lat, lon, alt, acc_m)
        if fix == last_fix:
            repeats += 1
            continue
        last_fix = fix
        kept.append((app, lat, lon, alt, acc_m))
    g = np.asarray(kept, dtype=np.float64).reshape(-1, 5)
    gnss_t, gnss_v, dup_n = _dedupe_sorted(np.round(g[:, 0] * 1e6).astype(np.int64), g[:, 1:])
    stats.update(gnss_lines=len(gnss), gnss_repeats_dropped=repeats + dup_n)

    # --- Wi-Fi scans: records within WIFI_GROUP_S of the scan's first AppTimestamp
    wifi.sort(key=lambda r: r[0])
    groups: list[list] = []
    for row in wifi:
        if not groups or row[0] - groups[-1][0][0] > WIFI_GROUP_S:
            groups.append([])
        groups[-1].append(row)
    max_age_ms = max_wifi_age_s * 1e3
    wifi_offset = offset
    if wifi and offset is not None:
        ages = np.array([r[0] - (r[1] + offset) for r in wifi])
        if abs(float(np.median(ages))) > 60.0:
            notes.append("WIFI SensorTimestamps are not on the inertial clock: no cached-entry check")
            wifi_offset = None
    elif wifi:
        notes.append("no inertial record to align the WIFI SensorTimestamps: no cached-entry check")
    scans, stale, dup_ap, empty = [], 0, 0, 0
    for rows in groups:
        t_scan = rows[0][0]
        best: dict[int, tuple] = {}
        for _app, sensor, bssid, rssi, freq in rows:
            age = math.nan if wifi_offset is None else (t_scan - (sensor + wifi_offset)) * 1e3
            if age > max_age_ms:
                stale += 1
                continue
            if bssid in best:
                dup_ap += 1
                if not age < best[bssid][3]:
                    continue
            best[bssid] = (bssid, rssi, freq, age)
        if not best:
            empty += 1
            continue
        ap = sorted(best.values())
        scans.append(
            WifiScan(
                t_us=int(round(t_scan * 1e6)),
                bssid=np.array([r[0] for r in ap], dtype=np.int64),
                rssi_dbm=np.array([r[1] for r in ap], dtype=np.float32),
                freq_mhz=np.array([r[2] for r in ap], dtype=np.int32),
                age_ms=np.array([r[3] for r in ap], dtype=np.float64),
            )
        )
    stats.update(
        wifi_lines=len(wifi),
        wifi_scans_in_file=len(groups),
        wifi_aps_written=sum(len(s.bssid) for s in scans),
        wifi_aps_stale_dropped=stale,
        wifi_aps_duplicate_dropped=dup_ap,
        wifi_scans_empty=empty,
        max_wifi_age_s=max_wifi_age_s,
        wifi_group_s=WIFI_GROUP_S,
    )

    # --- truth: POSI → local metres about the origin
    origin_source = None
    if origin is not None:
        origin, origin_source = (float(origin[0]), float(origin[1])), "option"
    elif posi:
        origin, origin_source = (posi[0][1], posi[0][2]), "first POSI"
    else:
        notes.append("no POSI record: no TRUTH message")
    building_ids = list(dict.fromkeys(r[4] for r in posi))
    order = sorted(range(len(posi)), key=lambda i: posi[i][0])
    posi = [posi[i] for i in order]
    truth_t = np.array([round(r[0] * 1e6) for r in posi], dtype=np.int64)
    latlon = np.array([(r[1], r[2]) for r in posi], dtype=np.float64).reshape(-1, 2)
    if posi:
        x, y = project(latlon[:, 0], latlon[:, 1], *origin)
        xy = np.column_stack([x, y])
    else:
        xy = np.zeros((0, 2))
    stats["posi_lines"] = len(posi)

    return GsdLog(
        path=path,
        header=header,
        imu_t_us=acc_t,
        accel_mps2=acc,
        gyro_radps=gyro,
        mag_t_us=mag_t,
        mag_ut=mag,
        baro_t_us=baro_t,
        baro_pa=baro,
        gnss_t_us=gnss_t,
        gnss=gnss_v,
        scans=scans,
        truth_t_us=truth_t,
        truth_xy_m=xy,
        truth_floor=np.array([r[3] for r in posi], dtype=np.int64),
        truth_latlon=latlon,
        building_ids=building_ids,
        origin=origin,
        origin_source=origin_source,
        stats=stats,
        skipped=skipped,
        notes=notes,
    )


def write_lcmlog(log: GsdLog, out_path) -> int:
    """Write ``log`` as an LCM event log (overwriting ``out_path``); returns the events written.

    Raises
    ------
    OSError
        The log cannot be written.
    """
    import lcm
    from stridefix import baro_t, gnss_t, imu_t, mag_t, truth_t, wifi_scan_t

    out_path = os.fspath(out_path)
    Path(out_path).parent.mkdir(parents=True, exist_ok=True)
    scan_t = np.array([s.t_us for s in log.scans], dtype=np.int64)
    times = [log.imu_t_us, log.mag_t_us, log.baro_t_us, log.gnss_t_us, scan_t, log.truth_t_us]
    t_all = np.concatenate(times)
    rank = np.concatenate([np.full(len(t), r) for r, t in enumerate(times)])
    index = np.concatenate([np.arange(len(t)) for t in times])
    order = np.lexsort((index, rank, t_all))

    def imu(i: int):
        m = imu_t()
        m.t_us, m.seq = int(log.imu_t_us[i]), i
        m.accel_mps2 = log.accel_mps2[i].tolist()
        m.gyro_radps = log.gyro_radps[i].tolist()
        return m

    def mag(i: int):
        m = mag_t()
        m.t_us, m.seq = int(log.mag_t_us[i]), i
        m.field_ut = log.mag_ut[i].tolist()
        return m

    def baro(i: int):
        m = baro_t()
        m.t_us, m.seq = int(log.baro_t_us[i]), i
        m.pressure_pa, m.temperature_degc = float(log.baro_pa[i]), float("nan")
        return m

    def gnss(i: int):
        m = gnss_t()
        m.t_us = int(log.gnss_t_us[i])
        m.lat_deg, m.lon_deg, m.alt_m, m.accuracy_m = (float(v) for v in log.gnss[i])
        return m

    def wifi(i: int):
        s = log.scans[i]
        m = wifi_scan_t()
        m.t_us, m.scan_id, m.complete, m.n_ap = s.t_us, i, True, len(s.bssid)
        m.bssid, m.rssi_dbm, m.freq_mhz = s.bssid.tolist(), s.rssi_dbm.tolist(), s.freq_mhz.tolist()
        return m

    def truth(i: int):
        m = truth_t()
        m.t_us = int(log.truth_t_us[i])
        m.x_m, m.y_m = (float(v) for v in log.truth_xy_m[i])
        m.floor, m.heading_rad, m.step_count = int(log.truth_floor[i]), float("nan"), -1
        m.source = truth_t.SOURCE_WAYPOINT
        return m

    makers = (imu, mag, baro, gnss, wifi, truth)
    out = lcm.EventLog(out_path, "w", overwrite=True)
    try:
        for r, i, t in zip(rank[order].tolist(), index[order].tolist(), t_all[order].tolist()):
            out.write_event(t, CHANNELS[r], makers[r](i).encode())
    finally:
        out.close()
    return len(order)


def import_log(
    path, out_path, origin: tuple[float, float] | None = None, max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S
) -> dict:
    """Read one logfile and write its LCM log; return :meth:`GsdLog.summary` plus ``out``, ``events``.

    Raises
    ------
    LogReadError
        The logfile is missing or unreadable (or its header unusable: :class:`LogHeaderError`).
    OSError
        The log cannot be written.
    """
    log = read_log(path, origin=origin, max_wifi_age_s=max_wifi_age_s)
    events = write_lcmlog(log, out_path)
    summary = log.summary()
    summary.update(out=os.fspath(out_path), events=events, importer_version=IMPORTER_VERSION)
    return summary


#: The name the msindoor importer uses (``import_trace(path, out_path, max_wifi_age_s=...)``), so code
#: that drives either importer (e.g. realbench's cached import) calls both alike.
import_trace = import_log


def format_summary(s: dict) -> str:
    """One line for the terminal."""
    m = s["messages"]
    rate = "-" if s["imu_rate_hz"] is None else f"{s['imu_rate_hz']:.0f} Hz"
    o = s["origin"]
    origin = "-" if o is None else f"{o['lat_deg']:.9f},{o['lon_deg']:.9f} ({o['source']})"
    floors = ",".join(str(f) for f in s["floors"]) or "-"
    return (
        f"{os.path.basename(s['trace'])}: {s['duration_s']:.1f} s, building "
        f"{s['building_id'] or ','.join(s['building_ids']) or '-'}, floor(s) {floors}, "
        f"IMU {m['IMU']} ({rate}), MAG {m['MAG']}, BARO {m['BARO']}, GNSS {m['GNSS']}, "
        f"WIFI {m['WIFI']} scans / {s['wifi_aps_written']} APs "
        f"({s['wifi_aps_stale_dropped']} cached dropped), TRUTH {m['TRUTH']} POSI, "
        f"origin {origin}, {s['skipped_lines']} malformed line(s) skipped"
    )


# --- `stridefix import gsd` ----------------------------------------------------------------------


def _origin_arg(text: str) -> tuple[float, float]:
    import argparse

    try:
        return parse_origin(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_parser(subparsers):
    """Declare ``stridefix import gsd``."""
    from stridefix_analyzer.datasets.cli import add_output_arguments

    p = subparsers.add_parser(
        "gsd",
        help="GetSensorData / IPIN Track 3 logfiles (*.txt)",
        description="Import GetSensorData logfiles (IPIN competition Track 3 format): one raw-sensor "
        "LCM log per logfile (IMU, MAG, BARO, GNSS, WIFI, TRUTH from the POSI records in "
        "local metres, x east, y north, about --origin), for "
        "`stridefixd --input lcmlog:FILE`.",
    )
    p.add_argument("logs", nargs="+", metavar="LOGFILE.txt", help="logfile(s)")
    add_output_arguments(p)
    p.add_argument(
        "--origin",
        type=_origin_arg,
        default=None,
        metavar="LAT,LON",
        help="origin of the truth's local metres [deg] (default: the file's first POSI; "
        "give one origin for all walks of a building; a negative latitude needs "
        "the = form: --origin=-33.9,151.2)",
    )
    p.add_argument(
        "--max-wifi-age-s",
        type=float,
        default=DEFAULT_MAX_WIFI_AGE_S,
        metavar="S",
        help="drop Wi-Fi entries last seen more than S before the scan time "
        f"(cached results; default {DEFAULT_MAX_WIFI_AGE_S:g})",
    )
    p.add_argument("--json", metavar="FILE", help="also write the summaries as JSON to FILE")
    return p


def run(args) -> int:
    """Import every logfile; exit 0, or 2 when one was missing/unreadable or output failed."""
    from stridefix_analyzer.datasets.cli import run_imports

    return run_imports(
        args,
        "stridefix import gsd",
        args.logs,
        lambda log, out: import_log(log, out, args.origin, args.max_wifi_age_s),
        LogReadError,
        format_summary,
        (
            "trace",
            "out",
            "messages",
            "skipped_lines",
            "duration_s",
            "waypoints",
            "building_id",
            "floors",
            "origin",
        ),
        "logfile",
    )
