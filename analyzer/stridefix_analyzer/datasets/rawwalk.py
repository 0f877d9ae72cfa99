"""The one container every data set reads a walk into: :class:`RawWalk`, named numpy columns per sensor.

A data set's ``read(path)`` (:mod:`.protocol`) returns a RawWalk and :func:`.lcmwrite.write_lcmlog`
turns any RawWalk into a raw-sensor LCM log, so a new format never touches LCM. Every stream is an
:class:`~stridefix_analyzer.io.logread.Table` sorted by ``t_us`` (int64 µs, the data set's common
clock) with units in the column names; a stream the set does not have is an empty table.

=======  ==========================================================================================
stream   columns
=======  ==========================================================================================
imu      t_us (n,), accel_mps2 (n, 3), gyro_radps (n, 3)
mag      t_us (m,), field_ut (m, 3)
baro     t_us (b,), pressure_pa (b,)
gnss     t_us (g,), lat_deg, lon_deg, alt_m, accuracy_m
wifi     one row per access point of a scan: scan (scan index 0, 1, ..., non-decreasing), t_us (the
         scan's time), bssid (int64), rssi_dbm (float32), freq_mhz (int32), age_ms (float64, NaN
         when unknown)
ble      one row per beacon of a BLE window (:func:`ble_scans`): scan (window index 0, 1, ...), t_us
         (the window's first reading), beacon_id (int64, 48-bit MAC), rssi_dbm (float32)
truth    t_us (w,), x_m, y_m (map metres), floor (int64): surveyed waypoints or reference positions
=======  ==========================================================================================

``meta`` holds what the set knows about the walk beyond samples (header fields, floor name, building
ids, projection origin), ``stats`` the import's counts, ``skipped`` the malformed lines and ``notes``
remarks for the summary; all JSON-ready.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from stridefix_analyzer.io.logread import Table

#: The columns of each stream (see the module docstring), in writing order.
STREAMS: dict[str, tuple[str, ...]] = {
    "imu": ("t_us", "accel_mps2", "gyro_radps"),
    "mag": ("t_us", "field_ut"),
    "baro": ("t_us", "pressure_pa"),
    "gnss": ("t_us", "lat_deg", "lon_deg", "alt_m", "accuracy_m"),
    "wifi": ("scan", "t_us", "bssid", "rssi_dbm", "freq_mhz", "age_ms"),
    "ble": ("scan", "t_us", "beacon_id", "rssi_dbm"),
    "truth": ("t_us", "x_m", "y_m", "floor"),
}


def empty(stream: str) -> Table:
    """A stream with no rows (vector columns keep their width 3)."""
    wide = {"accel_mps2", "gyro_radps", "field_ut"}
    return Table(
        {
            c: np.zeros((0, 3))
            if c in wide
            else np.zeros(0, np.int64 if c in ("t_us", "scan", "beacon_id") else float)
            for c in STREAMS[stream]
        }
    )


@dataclasses.dataclass
class RawWalk:
    """One walk as read from a data set's files, before LCM (see the module docstring).

    Raises
    ------
    ValueError
        On construction, when a stream lacks a column of :data:`STREAMS`.
    """

    path: str
    imu: Table = dataclasses.field(default_factory=lambda: empty("imu"))
    mag: Table = dataclasses.field(default_factory=lambda: empty("mag"))
    baro: Table = dataclasses.field(default_factory=lambda: empty("baro"))
    gnss: Table = dataclasses.field(default_factory=lambda: empty("gnss"))
    wifi: Table = dataclasses.field(default_factory=lambda: empty("wifi"))
    ble: Table = dataclasses.field(default_factory=lambda: empty("ble"))
    truth: Table = dataclasses.field(default_factory=lambda: empty("truth"))
    meta: dict[str, Any] = dataclasses.field(default_factory=dict)
    stats: dict[str, Any] = dataclasses.field(default_factory=dict)
    skipped: list[tuple[int, str]] = dataclasses.field(default_factory=list)
    notes: list[str] = dataclasses.field(default_factory=list)

    def __post_init__(self) -> None:
        for stream, cols in STREAMS.items():
            missing = [c for c in cols if c not in getattr(self, stream)]
            if missing:
                raise ValueError(f"{self.path}: RawWalk.{stream} lacks column(s) {missing}")

    @property
    def n_scans(self) -> int:
        """Number of Wi-Fi scans."""
        scan = self.wifi["scan"]
        return int(scan[-1]) + 1 if len(scan) else 0

    def scan_bounds(self) -> np.ndarray:
        """(n_scans + 1,) row offsets: scan i is rows ``bounds[i]:bounds[i + 1]`` of :attr:`wifi`."""
        return np.searchsorted(self.wifi["scan"], np.arange(self.n_scans + 1))

    def scan_t_us(self) -> np.ndarray:
        """(n_scans,) time of each scan [µs]."""
        t: np.ndarray = self.wifi["t_us"][self.scan_bounds()[:-1]]
        return t.astype(np.int64)

    @property
    def n_ble_scans(self) -> int:
        """Number of BLE windows (ble_scan_t messages)."""
        scan = self.ble["scan"]
        return int(scan[-1]) + 1 if len(scan) else 0

    def ble_bounds(self) -> np.ndarray:
        """(n_ble_scans + 1,) row offsets of the BLE windows in :attr:`ble`."""
        return np.searchsorted(self.ble["scan"], np.arange(self.n_ble_scans + 1))

    def ble_t_us(self) -> np.ndarray:
        """(n_ble_scans,) time of each BLE window [µs]."""
        t: np.ndarray = self.ble["t_us"][self.ble_bounds()[:-1]]
        return t.astype(np.int64)

    def scan(self, i: int) -> Table:
        """The access points of scan ``i``."""
        b = self.scan_bounds()
        return self.wifi.rows(slice(int(b[i]), int(b[i + 1])))

    def books(self) -> dict[str, Any]:
        """The import's books, the end of every summary: ``skipped_lines``, ``skipped`` (the first 100
        as line and reason), the :attr:`stats` and the ``notes``."""
        return {
            "skipped_lines": len(self.skipped),
            "skipped": [{"line": n, "reason": r} for n, r in self.skipped[:100]],
            **self.stats,
            "notes": list(self.notes),
        }

    def n_sensor_records(self) -> int:
        """Samples and scans of the sensor streams (imu, mag, baro, gnss, wifi; not truth): what a
        replay feeds ``stridefixd``. 0 means the walk holds nothing valid to import."""
        return (
            len(self.imu) + len(self.mag) + len(self.baro) + len(self.gnss) + self.n_scans + self.n_ble_scans
        )

    def time_span_us(self) -> tuple[int, int] | None:
        """(first, last) time of any sample [µs], or None for a walk without samples."""
        streams = (self.imu, self.mag, self.baro, self.gnss, self.wifi, self.ble, self.truth)
        ts = [s["t_us"] for s in streams if len(s)]
        if not ts:
            return None
        return int(min(t.min() for t in ts)), int(max(t.max() for t in ts))


# --- conversions the importers share ---------------------------------------------------------------


#: Times beyond ±this [s] are refused by the importers (10¹² s, some 31,700 years): the sum or
#: difference of any two accepted times, and so every clock offset, still fits LCM's int64 µs
#: (±9.2·10¹² s); a larger one would overflow where it is converted, not be skipped as bad data.
MAX_ABS_TIME_S = 1e12
#: what an int16 (``truth_t.floor``) and an int32 (``wifi_scan_t.freq_mhz``) hold
INT16_RANGE = (-(2**15), 2**15 - 1)
INT32_RANGE = (-(2**31), 2**31 - 1)


def times_s(values: list[float]) -> list[float]:
    """``values`` (times [s]) unchanged. Raises ValueError on one beyond :data:`MAX_ABS_TIME_S`."""
    for t in values:
        if not -MAX_ABS_TIME_S <= t <= MAX_ABS_TIME_S:
            raise ValueError(f"time {t:.6g} s beyond ±{MAX_ABS_TIME_S:g} s")
    return values


def unix_ms(text: str) -> int:
    """A time field of unsigned ASCII digits [ms]. Raises ValueError on another form or a time beyond
    :data:`MAX_ABS_TIME_S` (``int()`` alone takes ``²``, ``+1``, ``1_000`` and any length)."""
    if not (text.isascii() and text.isdigit()):
        raise ValueError(f"time {text[:40]!r} is not unsigned digits")
    if len(text) > 16 or int(text) > MAX_ABS_TIME_S * 1000:
        raise ValueError(f"time {text[:20]}{'...' if len(text) > 20 else ''} ms beyond {MAX_ABS_TIME_S:g} s")
    return int(text)


def bounded_int(text: str, bounds: tuple[int, int], what: str) -> int:
    """An integer field within ``bounds`` (inclusive), e.g. :data:`INT32_RANGE` for what an int32
    column holds. Raises ValueError naming ``what`` otherwise."""
    text = text.strip()
    if len(text) > 20:  # also keeps int() off a 5000-digit field
        raise ValueError(f"{what} {text[:20]}... outside {bounds[0]}..{bounds[1]}")
    value = int(text)
    if not bounds[0] <= value <= bounds[1]:
        raise ValueError(f"{what} {value} outside {bounds[0]}..{bounds[1]}")
    return value


def finite(values: list[str]) -> list[float]:
    """The fields as floats. Raises ValueError on a field that is not a finite number."""
    out = list(map(float, values))
    if not all(map(math.isfinite, out)):  # map, not a generator: called once per sensor record
        raise ValueError("non-finite value")
    return out


def dedupe_sorted(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Stable sort by time and keep the first sample of each time; returns (t, v, dropped)."""
    order = np.argsort(t, kind="stable")
    t, v = t[order], v[order]
    keep = np.ones(len(t), dtype=bool)
    keep[1:] = t[1:] != t[:-1]
    return t[keep], v[keep], int((~keep).sum())


def gyro_at(
    acc_t: np.ndarray, gyr_t: np.ndarray, gyr: np.ndarray, notes: list[str], missing: str
) -> tuple[np.ndarray, int]:
    """Gyroscope (k, 3) interpolated linearly to the accelerometer times ``acc_t`` (held at the end
    values outside its span) and the number of accelerometer times so held. Without gyro data: zeros,
    all held, and the note "no ``missing``: gyro written as 0" when there are accelerometer samples."""
    if not len(gyr_t):
        if len(acc_t):
            notes.append(f"no {missing}: gyro written as 0")
        return np.zeros((len(acc_t), 3)), len(acc_t)
    gyro = np.column_stack([np.interp(acc_t, gyr_t, gyr[:, i]) for i in range(3)])
    return gyro, int(((acc_t < gyr_t[0]) | (acc_t > gyr_t[-1])).sum())


def freshest(
    entries: list[tuple[int, float, int, float]], max_age_ms: float
) -> tuple[list[tuple[int, float, int, float]], int, int]:
    """One scan's (bssid, rssi_dbm, freq_mhz, age_ms) entries without cached results (age above
    ``max_age_ms``) and with the freshest entry of a BSSID heard twice (the first one when ages are
    unknown, NaN). Returns (entries sorted by BSSID, stale dropped, duplicates dropped)."""
    best: dict[int, tuple[int, float, int, float]] = {}
    stale = dup = 0
    for bssid, rssi, freq, age in entries:
        if age > max_age_ms:
            stale += 1
            continue
        if bssid in best:
            dup += 1
            if not age < best[bssid][3]:
                continue
        best[bssid] = (bssid, rssi, freq, age)
    return sorted(best.values()), stale, dup


def wifi_table(scans: list[tuple[int, list[tuple[int, float, int, float]]]]) -> Table:
    """The :attr:`RawWalk.wifi` stream of (t_us, entries) scans (entries as :func:`freshest` returns)."""
    rows = [(i, t, *e) for i, (t, entries) in enumerate(scans) for e in entries]
    cols: list[Sequence[object]] = list(zip(*rows)) if rows else [[] for _ in STREAMS["wifi"]]
    dtypes = (np.int64, np.int64, np.int64, np.float32, np.int32, np.float64)
    return Table({n: np.asarray(c, dtype=d) for n, c, d in zip(STREAMS["wifi"], cols, dtypes)})


def wifi_scans(
    scans: list[tuple[int, list[tuple[int, float, int, float]]]], max_wifi_age_s: float, stats: dict[str, Any]
) -> Table:
    """The :attr:`RawWalk.wifi` stream of the file's scans, (t_us, entries) in time order: each scan
    :func:`freshest` (cached entries older than ``max_wifi_age_s`` [s] dropped), scans left empty left
    out. The counts go into ``stats`` (``wifi_lines``, ``wifi_scans_in_file``, ``wifi_aps_written``,
    ``wifi_aps_stale_dropped``, ``wifi_aps_duplicate_dropped``, ``wifi_scans_empty``, ``max_wifi_age_s``)."""
    kept, stale, dup, empty = [], 0, 0, 0
    for t_us, entries in scans:
        fresh, n_stale, n_dup = freshest(entries, max_wifi_age_s * 1e3)
        stale, dup = stale + n_stale, dup + n_dup
        if fresh:
            kept.append((t_us, fresh))
        else:
            empty += 1
    stats.update(
        wifi_lines=sum(len(e) for _, e in scans),
        wifi_scans_in_file=len(scans),
        wifi_aps_written=sum(len(e) for _, e in kept),
        wifi_aps_stale_dropped=stale,
        wifi_aps_duplicate_dropped=dup,
        wifi_scans_empty=empty,
        max_wifi_age_s=max_wifi_age_s,
    )
    return wifi_table(kept)


#: One ble_scan_t holds the advertisements of this window [s] from its first one: beacons advertise
#: every 0.1–1 s (iBeacon/Eddystone practice), so a window hears most beacons in range once or more,
#: while a walker (~1.4 m/s) moves about a metre in it, less than the range model resolves.
BLE_WINDOW_S = 1.0


def ble_scans(readings: list[tuple[int, int, float]], stats: dict[str, Any]) -> Table:
    """The :attr:`RawWalk.ble` stream of (t_us, beacon_id, rssi_dbm) readings: windows of
    :data:`BLE_WINDOW_S` from each window's first reading, a beacon heard more than once in a window
    written once at its mean RSSI [dBm] (rows sorted by id). Counts into ``stats``: ``ble_readings``,
    ``ble_scans``, ``ble_beacons`` (distinct ids), ``ble_repeats_merged``, ``ble_window_s``."""
    windows: list[tuple[int, dict[int, list[float]]]] = []
    for t_us, beacon, rssi in sorted(readings, key=lambda r: r[0]):
        if not windows or t_us - windows[-1][0] >= BLE_WINDOW_S * 1e6:
            windows.append((t_us, {}))
        windows[-1][1].setdefault(beacon, []).append(rssi)
    rows = [
        (scan, t0, beacon, float(np.mean(heard[beacon])))
        for scan, (t0, heard) in enumerate(windows)
        for beacon in sorted(heard)
    ]
    merged = len(readings) - len(rows)
    stats.update(
        ble_readings=len(readings),
        ble_scans=len(windows),
        ble_beacons=len({r[1] for r in readings}),
        ble_repeats_merged=merged,
        ble_window_s=BLE_WINDOW_S,
    )
    cols: list[Sequence[object]] = list(zip(*rows)) if rows else [[] for _ in STREAMS["ble"]]
    dtypes = (np.int64, np.int64, np.int64, np.float32)
    return Table({n: np.asarray(c, dtype=d) for n, c, d in zip(STREAMS["ble"], cols, dtypes)})


def bssid_to_int(bssid: str) -> int:
    """``aa:bb:cc:dd:ee:ff`` → 0xaabbccddeeff (48-bit int). Raises ValueError on another form."""
    if not _BSSID_RE.match(bssid):
        raise ValueError(f"BSSID {bssid!r} is not six hex pairs")
    return int(bssid.replace(":", ""), 16)


_BSSID_RE = re.compile(r"^[0-9A-Fa-f]{2}(:[0-9A-Fa-f]{2}){5}$")
