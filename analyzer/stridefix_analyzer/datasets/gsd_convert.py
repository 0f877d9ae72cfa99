"""Conversion of a GetSensorData logfile's records (:mod:`.gsd_parse`) into a :class:`~.rawwalk.RawWalk`.

Clocks: ``t_us`` = AppTimestamp [s] × 10⁶ (the common clock of all records), except the inertial
samples (ACCE, GYRO and MAGN, one sensor clock): those are timed by their SensorTimestamps,
``t = SensorTimestamp + offset``, one constant offset for the file = the median of AppTimestamp −
SensorTimestamp over the inertial samples of the first :data:`CLOCK_ALIGN_S` seconds (the first few
samples arrive 40–75 ms late, so the first pair alone is a poor anchor). So the inertial time steps are
the sensor's own and the streams still share the clock of Wi-Fi, GNSS and the truth. Everything is
kept, the calibration minute included; the truth starts at the first POSI.

* ``imu``: ACCE (m/s²) with GYRO (rad/s) interpolated linearly to the accelerometer times; ``mag``: MAGN.
* ``baro``: PRES converted to Pa from the header's unit (mbar/hPa ×100, kPa ×1000, Pa).
* ``gnss``: the app logs most fixes twice (same fix time = SensorTimestamp): the repeats are dropped.
* ``wifi``: one scan = the WIFI records whose AppTimestamps lie within :data:`WIFI_GROUP_S` of the scan's
  first one; an entry last seen (its SensorTimestamp, on the inertial clock) more than
  ``max_wifi_age_s`` before the scan is a cached result, dropped; a BSSID heard twice keeps its
  freshest entry.
* ``ble``: BLE4 records (iBeacon and Eddystone; the MAC is the beacon id) on the app clock, grouped
  into windows of :data:`~.rawwalk.BLE_WINDOW_S` (:func:`~.rawwalk.ble_scans`: the app logs one
  record per advertisement, with no scan grouping of its own).
* ``truth``: POSI latitude/longitude → local metres, x east and y north, by a local tangent plane about
  an origin (:func:`stridefix_common.geodesy.project`); floor = the floor id. The building ids go into ``meta``.
"""

from __future__ import annotations

import math

import numpy as np
from stridefix_common.geodesy import project

from stridefix_analyzer.datasets.gsd_parse import INERTIAL, GsdRecords
from stridefix_analyzer.datasets.rawwalk import RawWalk, ble_scans, dedupe_sorted, gyro_at, wifi_scans
from stridefix_analyzer.io.logread import Table

#: WIFI records whose AppTimestamps lie within this of a scan's first record belong to that scan [s].
WIFI_GROUP_S = 0.010
#: The sensor → app clock offset is the median over the inertial samples of the first S seconds.
CLOCK_ALIGN_S = 10.0


def parse_origin(text: str) -> tuple[float, float]:
    """``"LAT,LON"`` [deg] → (lat, lon). Raises ValueError on another form or out-of-range values."""
    parts = text.replace(" ", "").split(",")
    if len(parts) != 2:
        raise ValueError(f"origin {text!r} is not LAT,LON")
    lat, lon = (float(p) for p in parts)
    if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0):
        raise ValueError(f"origin {text!r} out of range (latitude ±90, longitude ±180)")
    return lat, lon


def _inertial(
    rec: GsdRecords, stats: dict[str, object], notes: list[str]
) -> tuple[Table, Table, float | None]:
    """``imu`` and ``mag`` on the app clock, and the sensor → app offset [s] (None: no inertial data)."""
    arrays = {k: np.asarray(v, dtype=np.float64).reshape(-1, 5) for k, v in rec.inertial.items()}
    offset, per_type = None, {}
    for k, a in arrays.items():
        if len(a):
            start = a[a[:, 0] <= a[:, 0].min() + CLOCK_ALIGN_S]
            per_type[k] = float(np.median(start[:, 0] - start[:, 1]))
    base: list[str] = [k for k in ("ACCE", "GYRO") if k in per_type] or list(per_type)
    if base:
        a = np.concatenate([arrays[k] for k in base])
        start = a[a[:, 0] <= a[:, 0].min() + CLOCK_ALIGN_S]
        offset = float(np.median(start[:, 0] - start[:, 1]))
    offsets = {}
    for k, off in per_type.items():
        assert offset is not None  # per_type is not empty, so neither is base
        if abs(off - offset) > 1.0:  # a sensor on another clock: align it on its own
            notes.append(
                f"{k} SensorTimestamps are {off - offset:+.3f} s off the inertial clock: aligned separately"
            )
            offsets[k] = off
        else:
            offsets[k] = offset
    stats["clock_offset_s"] = offset  # app time = sensor time + offset
    stats["clock_align_s"] = CLOCK_ALIGN_S

    def sensor_times(k: str) -> tuple[np.ndarray, np.ndarray, int]:
        a = arrays[k]
        if not len(a):
            return dedupe_sorted(np.zeros(0, dtype=np.int64), np.zeros((0, 3)))
        return dedupe_sorted(np.round((a[:, 1] + offsets[k]) * 1e6).astype(np.int64), a[:, 2:5])

    (acc_t, acc, dup_a), (gyr_t, gyr, dup_g), (mag_t, mag, dup_m) = map(sensor_times, INERTIAL)
    gyro, held = gyro_at(acc_t, gyr_t, gyr, notes, "GYRO record")
    if not len(acc_t):
        notes.append("no ACCE record: no IMU message")
    stats["imu_gyro_held"] = held
    stats["gyro_samples"] = len(gyr_t)
    stats["gyro_rate_hz"] = float(1e6 / np.median(np.diff(gyr_t))) if len(gyr_t) > 1 else None
    stats["duplicate_times_dropped"] = {"ACCE": dup_a, "GYRO": dup_g, "MAGN": dup_m}
    imu = Table({"t_us": acc_t, "accel_mps2": acc, "gyro_radps": gyro})
    return imu, Table({"t_us": mag_t, "field_ut": mag}), offset


def _baro_gnss(rec: GsdRecords, stats: dict[str, object]) -> tuple[Table, Table]:
    """``baro`` and ``gnss`` on the app clock (GNSS repeats dropped)."""
    p = np.asarray(rec.pres, dtype=np.float64).reshape(-1, 3)
    baro_t, baro, dup_p = dedupe_sorted(np.round(p[:, 0] * 1e6).astype(np.int64), p[:, 2] * rec.pa_per_unit)
    dups = stats["duplicate_times_dropped"]
    assert isinstance(dups, dict)
    dups["PRES"] = dup_p
    gnss = sorted(rec.gnss, key=lambda r: r[0])
    kept, repeats = [], 0
    last_fix: tuple[float, ...] | None = None
    for app, sensor, lat, lon, alt, acc_m in gnss:
        fix = (sensor, lat, lon, alt, acc_m)
        if fix == last_fix:
            repeats += 1
            continue
        last_fix = fix
        kept.append((app, lat, lon, alt, acc_m))
    g = np.asarray(kept, dtype=np.float64).reshape(-1, 5)
    gnss_t, gnss_v, dup_n = dedupe_sorted(np.round(g[:, 0] * 1e6).astype(np.int64), g[:, 1:])
    stats.update(gnss_lines=len(gnss), gnss_repeats_dropped=repeats + dup_n)
    names = ("lat_deg", "lon_deg", "alt_m", "accuracy_m")
    return (
        Table({"t_us": baro_t, "pressure_pa": baro}),
        Table({"t_us": gnss_t, **{n: gnss_v[:, i] for i, n in enumerate(names)}}),
    )


def _wifi(
    rec: GsdRecords, offset: float | None, max_wifi_age_s: float, stats: dict[str, object], notes: list[str]
) -> Table:
    """``wifi``: records grouped into scans, cached and repeated entries dropped."""
    wifi = sorted(rec.wifi, key=lambda r: r[0])
    groups: list[list[tuple[float, float, int, float, int]]] = []
    for row in wifi:
        if not groups or row[0] - groups[-1][0][0] > WIFI_GROUP_S:
            groups.append([])
        groups[-1].append(row)
    wifi_offset = offset
    if wifi and offset is not None:
        ages = np.array([r[0] - (r[1] + offset) for r in wifi])
        if abs(float(np.median(ages))) > 60.0:
            notes.append("WIFI SensorTimestamps are not on the inertial clock: no cached-entry check")
            wifi_offset = None
    elif wifi:
        notes.append("no inertial record to align the WIFI SensorTimestamps: no cached-entry check")
    scans = []
    for rows in groups:
        t_scan = rows[0][0]
        entries = [
            (bssid, rssi, freq, math.nan if wifi_offset is None else (t_scan - (sensor + wifi_offset)) * 1e3)
            for _app, sensor, bssid, rssi, freq in rows
        ]
        scans.append((int(round(t_scan * 1e6)), entries))
    table = wifi_scans(scans, max_wifi_age_s, stats)
    stats["wifi_group_s"] = WIFI_GROUP_S
    return table


def to_rawwalk(rec: GsdRecords, origin: tuple[float, float] | None, max_wifi_age_s: float) -> RawWalk:
    """The walk of one logfile's records (see the module docstring).

    ``origin`` (lat, lon) [deg] of the truth's local metres; None: the file's first POSI record.
    ``meta``: ``header`` (device lines), ``building_ids`` (distinct POSI building ids in file order),
    ``origin`` (lat, lon or None), ``origin_source`` ("option" or "first POSI"), ``truth_latlon``.
    """
    notes: list[str] = []
    if rec.pressure_unit is None and rec.pres:
        notes.append("no PRES format line in the header: pressure taken as mbar")
    stats: dict[str, object] = {
        "lines": rec.n_lines,
        "ignored_lines_by_type": dict(sorted(rec.ignored.items())),
        "pressure_unit": rec.pressure_unit or "mbar (assumed)",
    }
    imu, mag, offset = _inertial(rec, stats, notes)
    baro, gnss = _baro_gnss(rec, stats)
    wifi = _wifi(rec, offset, max_wifi_age_s, stats, notes)
    ble = ble_scans([(int(round(t * 1e6)), mac, rssi) for t, mac, rssi in rec.ble], stats)

    posi, origin_source = rec.posi, None
    if origin is not None:
        origin, origin_source = (float(origin[0]), float(origin[1])), "option"
    elif posi:
        origin, origin_source = (posi[0][1], posi[0][2]), "first POSI"
    else:
        notes.append("no POSI record: no TRUTH message")
    building_ids = list(dict.fromkeys(r[4] for r in posi))
    posi = sorted(posi, key=lambda r: r[0])
    truth_t = np.array([round(r[0] * 1e6) for r in posi], dtype=np.int64)
    latlon = np.array([(r[1], r[2]) for r in posi], dtype=np.float64).reshape(-1, 2)
    if posi and origin is not None:
        x, y = project(latlon[:, 0], latlon[:, 1], *origin)
    else:
        x, y = np.zeros(0), np.zeros(0)
    stats["posi_lines"] = len(posi)
    floor = np.array([r[3] for r in posi], dtype=np.int64)
    return RawWalk(
        path=rec.path,
        imu=imu,
        mag=mag,
        baro=baro,
        gnss=gnss,
        wifi=wifi,
        ble=ble,
        truth=Table({"t_us": truth_t, "x_m": x, "y_m": y, "floor": floor}),
        meta={
            "header": rec.header,
            "building_ids": building_ids,
            "origin": origin,
            "origin_source": origin_source,
            "truth_latlon": latlon,
        },
        stats=stats,
        skipped=rec.skipped,
        notes=notes,
    )
