"""Importer of the Microsoft Indoor Location Competition 2.0 traces (real Android phone walks).

One trace file (``../shared/data/msindoor/<site>/<floor>/path_data_files/*.txt``, format in that
folder's README) becomes one raw-sensor LCM event log that ``stridefixd --input lcmlog:FILE`` replays:

=======  ===========  =====================================================================================
channel  type         from
=======  ===========  =====================================================================================
IMU      imu_t        TYPE_ACCELEROMETER (m/s²), with TYPE_GYROSCOPE (rad/s) linearly interpolated to the
                      accelerometer times (held at the end values outside the gyroscope's time span);
                      seq = 0, 1, ... in time order. The ``*_UNCALIBRATED`` variants are not used.
MAG      mag_t        TYPE_MAGNETIC_FIELD (µT)
WIFI     wifi_scan_t  one scan = the TYPE_WIFI lines sharing a first-column time; BSSID ``aa:bb:..:ff`` →
                      0xaabb..ff; frequency from the file; entries whose last_seen time is more than
                      ``max_wifi_age_s`` older than the scan time are cached results and dropped; a
                      BSSID heard twice in one scan keeps its freshest entry; a scan left empty is not
                      written (counted)
TRUTH    truth_t      TYPE_WAYPOINT: x_m, y_m, floor index from the FloorName header (F1 → 0, F2 → 1,
                      B1 → −1, ...), heading NaN, step_count −1, source SOURCE_WAYPOINT
=======  ===========  =====================================================================================

Times: ``t_us`` = the file's unix time [ms] × 1000 (sensor event time and Wi-Fi system time alike);
the LCM event timestamp is ``t_us`` and events are written in time order (ties: IMU, MAG, WIFI, TRUTH).

Bad data is not an error: a malformed line (two records run together, wrong field count, a field that
is not a number) is counted, skipped and reported with a :class:`MalformedLineWarning` naming file and
line. A missing or unreadable file raises :class:`TraceReadError` naming it; a FloorName that cannot be
mapped to a floor index raises :class:`TraceHeaderError` unless the floor is given.

Cost: one pass over the text (~1 s per 10⁵ lines), memory ∝ the samples of one trace.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from pathlib import Path

import numpy as np

from stridefix_analyzer.datasets.lines import LineReader, MalformedLineWarning  # noqa: F401  (re-exported for callers)

#: Bump when the log content for the same input changes (caches compare it).
IMPORTER_VERSION = 1
#: Default age beyond which a Wi-Fi entry counts as cached [s] (issue 5: "more than ~2 s older than
#: its scan is a cached entry").
DEFAULT_MAX_WIFI_AGE_S = 2.0
#: Malformed lines reported one by one per file; the rest are summed up in one warning.
MAX_LINE_WARNINGS = 20

CHANNELS = ("IMU", "MAG", "WIFI", "TRUTH")  # also the tie-break order of equal times

_SENSOR_TYPES = {"TYPE_ACCELEROMETER": "accel", "TYPE_GYROSCOPE": "gyro", "TYPE_MAGNETIC_FIELD": "mag"}
# record type -> number of tab-separated fields, time and type included
_FIELDS = {
    "TYPE_ACCELEROMETER": 6,
    "TYPE_GYROSCOPE": 6,
    "TYPE_MAGNETIC_FIELD": 6,
    "TYPE_WIFI": 7,
    "TYPE_WAYPOINT": 4,
}
_BSSID_RE = re.compile(r"^[0-9A-Fa-f]{2}(:[0-9A-Fa-f]{2}){5}$")


class TraceReadError(Exception):
    """A trace file is missing or cannot be read. The message names the file."""

    def __init__(self, path, reason: str):
        super().__init__(f"{path}: {reason}")
        self.path = str(path)
        self.reason = reason


class TraceHeaderError(TraceReadError):
    """The trace's header lacks what the import needs (e.g. an unknown FloorName)."""


def floor_index(name: str) -> int:
    """Floor index of a FloorName: ``F1``/``1F``/``L1``/``G`` → 0, ``F2`` → 1, ``B1``/``1B`` → −1.

    Raises
    ------
    ValueError
        The name follows none of these patterns.
    """
    s = name.strip().upper()
    if s in ("G", "GF"):
        return 0
    m = re.fullmatch(r"(?:F|L)(\d+)|(\d+)F", s)
    if m and int(m.group(1) or m.group(2)) >= 1:
        return int(m.group(1) or m.group(2)) - 1
    m = re.fullmatch(r"B(\d+)|(\d+)B", s)
    if m and int(m.group(1) or m.group(2)) >= 1:
        return -int(m.group(1) or m.group(2))
    raise ValueError(f"floor name {name!r} is not F<n>, <n>F, L<n>, G, B<n> or <n>B")


def bssid_to_int(bssid: str) -> int:
    """``aa:bb:cc:dd:ee:ff`` → 0xaabbccddeeff (48-bit int). Raises ValueError on another form."""
    if not _BSSID_RE.match(bssid):
        raise ValueError(f"BSSID {bssid!r} is not six hex pairs")
    return int(bssid.replace(":", ""), 16)


@dataclasses.dataclass
class WifiScan:
    """One scan as written: time [ms], and per AP (n,) bssid, rssi_dbm, freq_mhz, age_ms."""

    t_ms: int
    bssid: np.ndarray
    rssi_dbm: np.ndarray
    freq_mhz: np.ndarray
    age_ms: np.ndarray


@dataclasses.dataclass
class Trace:
    """One parsed trace, in time order, ready to write.

    Attributes
    ----------
    imu_t_ms : (n,) int64, strictly increasing accelerometer times [ms]
    accel_mps2, gyro_radps : (n, 3) float64 (gyro interpolated to ``imu_t_ms``)
    mag_t_ms : (m,) int64; mag_ut : (m, 3) float64 [µT]
    scans : list of WifiScan (non-empty scans only)
    waypoint_t_ms : (w,) int64; waypoint_xy_m : (w, 2) float64
    floor : int, floor index of the waypoints
    header : dict, the ``key:value`` pairs of the ``#`` lines
    stats : dict, the counts reported by :meth:`summary`
    skipped : list of (line number, reason), every malformed line
    """

    path: str
    header: dict
    floor_name: str
    floor: int
    imu_t_ms: np.ndarray
    accel_mps2: np.ndarray
    gyro_radps: np.ndarray
    mag_t_ms: np.ndarray
    mag_ut: np.ndarray
    scans: list
    waypoint_t_ms: np.ndarray
    waypoint_xy_m: np.ndarray
    stats: dict
    skipped: list
    notes: list

    def time_span_ms(self) -> tuple[int, int] | None:
        """(first, last) time of anything written [ms], or None for an empty trace."""
        ts = [a for a in (self.imu_t_ms, self.mag_t_ms, self.waypoint_t_ms) if len(a)]
        ts += [np.array([s.t_ms for s in self.scans])] if self.scans else []
        if not ts:
            return None
        return int(min(a.min() for a in ts)), int(max(a.max() for a in ts))

    def summary(self) -> dict:
        """Counts per channel, skipped lines, duration, waypoints: a JSON-ready dict."""
        span = self.time_span_ms()
        dt = np.diff(self.imu_t_ms)
        return {
            "trace": self.path,
            "site_id": self.header.get("SiteID"),
            "floor_name": self.floor_name,
            "floor": self.floor,
            "messages": {
                "IMU": len(self.imu_t_ms),
                "MAG": len(self.mag_t_ms),
                "WIFI": len(self.scans),
                "TRUTH": len(self.waypoint_t_ms),
            },
            "waypoints": len(self.waypoint_t_ms),
            "t_start_us": None if span is None else span[0] * 1000,
            "t_end_us": None if span is None else span[1] * 1000,
            "duration_s": 0.0 if span is None else (span[1] - span[0]) / 1e3,
            "imu_t_first_us": int(self.imu_t_ms[0]) * 1000 if len(self.imu_t_ms) else None,
            "imu_t_last_us": int(self.imu_t_ms[-1]) * 1000 if len(self.imu_t_ms) else None,
            "imu_rate_hz": float(1e3 / np.median(dt)) if len(dt) else None,
            "imu_max_gap_ms": int(dt.max()) if len(dt) else None,
            "skipped_lines": len(self.skipped),
            "skipped": [{"line": n, "reason": r} for n, r in self.skipped[:100]],
            **self.stats,
            "notes": list(self.notes),
        }


def _dedupe_sorted(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Stable sort by time and keep the first sample of each time; returns (t, v, dropped)."""
    order = np.argsort(t, kind="stable")
    t, v = t[order], v[order]
    keep = np.ones(len(t), dtype=bool)
    keep[1:] = t[1:] != t[:-1]
    return t[keep], v[keep], int((~keep).sum())


def _finite(values: list[str]) -> list[float]:
    out = [float(x) for x in values]
    if not all(math.isfinite(x) for x in out):
        raise ValueError("non-finite value")
    return out


def read_trace(
    path,
    max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S,
    floor: int | None = None,
    max_line_warnings: int = MAX_LINE_WARNINGS,
) -> Trace:
    """Parse one trace file.

    Parameters
    ----------
    path : str or path
        The trace (tab-separated text).
    max_wifi_age_s : float
        Wi-Fi entries with scan time − last_seen time above this [s] are cached results, dropped.
    floor : int, optional
        Floor index of the waypoints; default: from the FloorName header.
    max_line_warnings : int
        Malformed lines warned about one by one; further ones are summed up in one warning.

    Raises
    ------
    TraceReadError
        The file is missing, not a file, or unreadable.
    TraceHeaderError
        No usable FloorName header and ``floor`` not given.
    """
    reader = LineReader(path, TraceReadError, max_line_warnings)
    path = reader.path
    samples = {"accel": [], "gyro": [], "mag": []}
    wifi: dict[int, list] = {}
    waypoints = []
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
        if len(parts) < 2 or not parts[0].isdigit():
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
        t_ms = int(parts[0])
        try:
            if kind == "TYPE_WIFI":
                entry = (bssid_to_int(parts[3]), _finite(parts[4:5])[0], int(parts[5]), int(parts[6]))
                wifi.setdefault(t_ms, []).append(entry)
            elif kind == "TYPE_WAYPOINT":
                waypoints.append((t_ms, *_finite(parts[2:4])))
            else:
                samples[_SENSOR_TYPES[kind]].append((t_ms, *_finite(parts[2:5])))
        except ValueError as exc:
            bad(line_no, f"{kind}: {exc}")
    reader.finish()
    skipped, ignored, n_lines = reader.skipped, reader.ignored, reader.n_lines

    floor_name = header.get("FloorName", "")
    if floor is None:
        try:
            floor = floor_index(floor_name)
        except ValueError as exc:
            raise TraceHeaderError(path, f"no floor index: {exc} (pass the floor explicitly)") from None
    notes: list[str] = []
    stats: dict = {"lines": n_lines, "ignored_lines_by_type": dict(sorted(ignored.items()))}

    def columns(rows: list, width: int) -> tuple[np.ndarray, np.ndarray]:
        if not rows:
            return np.zeros(0, dtype=np.int64), np.zeros((0, width))
        a = np.asarray(rows, dtype=np.float64)
        return a[:, 0].astype(np.int64), a[:, 1:]

    acc_t, acc = columns(samples["accel"], 3)
    gyr_t, gyr = columns(samples["gyro"], 3)
    mag_t, mag = columns(samples["mag"], 3)
    acc_t, acc, dup_a = _dedupe_sorted(acc_t, acc)
    gyr_t, gyr, dup_g = _dedupe_sorted(gyr_t, gyr)
    mag_t, mag, dup_m = _dedupe_sorted(mag_t, mag)
    stats["duplicate_times_dropped"] = {"accel": dup_a, "gyro": dup_g, "mag": dup_m}
    if len(gyr_t):
        gyro = np.column_stack([np.interp(acc_t, gyr_t, gyr[:, i]) for i in range(3)])
        held = int(((acc_t < gyr_t[0]) | (acc_t > gyr_t[-1])).sum())
    else:
        gyro, held = np.zeros_like(acc), len(acc_t)
        if len(acc_t):
            notes.append("no TYPE_GYROSCOPE line: gyro written as 0")
    stats["imu_gyro_held"] = held
    if not len(acc_t):
        notes.append("no TYPE_ACCELEROMETER line: no IMU message")

    max_age_ms = max_wifi_age_s * 1e3
    scans, stale, dup_ap, empty = [], 0, 0, 0
    for t_ms in sorted(wifi):
        best: dict[int, tuple] = {}
        for bssid, rssi, freq, last_seen in wifi[t_ms]:
            age = t_ms - last_seen
            if age > max_age_ms:
                stale += 1
                continue
            if bssid in best:
                dup_ap += 1
                if age >= best[bssid][3]:
                    continue
            best[bssid] = (bssid, rssi, freq, age)
        if not best:
            empty += 1
            continue
        rows = sorted(best.values())
        scans.append(
            WifiScan(
                t_ms=t_ms,
                bssid=np.array([r[0] for r in rows], dtype=np.int64),
                rssi_dbm=np.array([r[1] for r in rows], dtype=np.float32),
                freq_mhz=np.array([r[2] for r in rows], dtype=np.int32),
                age_ms=np.array([r[3] for r in rows], dtype=np.int64),
            )
        )
    stats.update(
        wifi_lines=sum(len(v) for v in wifi.values()),
        wifi_scans_in_file=len(wifi),
        wifi_aps_written=sum(len(s.bssid) for s in scans),
        wifi_aps_stale_dropped=stale,
        wifi_aps_duplicate_dropped=dup_ap,
        wifi_scans_empty=empty,
        max_wifi_age_s=max_wifi_age_s,
    )

    waypoints.sort(key=lambda w: w[0])
    wp_t = np.array([w[0] for w in waypoints], dtype=np.int64)
    wp_xy = np.array([w[1:] for w in waypoints], dtype=np.float64).reshape(-1, 2)
    return Trace(
        path=path,
        header=header,
        floor_name=floor_name,
        floor=int(floor),
        imu_t_ms=acc_t,
        accel_mps2=acc,
        gyro_radps=gyro,
        mag_t_ms=mag_t,
        mag_ut=mag,
        scans=scans,
        waypoint_t_ms=wp_t,
        waypoint_xy_m=wp_xy,
        stats=stats,
        skipped=skipped,
        notes=notes,
    )


def write_lcmlog(trace: Trace, out_path) -> int:
    """Write ``trace`` as an LCM event log (overwriting ``out_path``); returns the events written.

    Raises
    ------
    OSError
        The log cannot be written.
    """
    import lcm
    from stridefix import imu_t, mag_t, truth_t, wifi_scan_t

    out_path = os.fspath(out_path)
    Path(out_path).parent.mkdir(parents=True, exist_ok=True)
    scan_t = np.array([s.t_ms for s in trace.scans], dtype=np.int64)
    times = [trace.imu_t_ms, trace.mag_t_ms, scan_t, trace.waypoint_t_ms]
    t_all = np.concatenate(times)
    rank = np.concatenate([np.full(len(t), r) for r, t in enumerate(times)])
    index = np.concatenate([np.arange(len(t)) for t in times])
    order = np.lexsort((index, rank, t_all))

    def imu(i: int):
        m = imu_t()
        m.t_us, m.seq = int(trace.imu_t_ms[i]) * 1000, i
        m.accel_mps2 = trace.accel_mps2[i].tolist()
        m.gyro_radps = trace.gyro_radps[i].tolist()
        return m

    def mag(i: int):
        m = mag_t()
        m.t_us, m.seq = int(trace.mag_t_ms[i]) * 1000, i
        m.field_ut = trace.mag_ut[i].tolist()
        return m

    def wifi(i: int):
        s = trace.scans[i]
        m = wifi_scan_t()
        m.t_us, m.scan_id, m.complete, m.n_ap = s.t_ms * 1000, i, True, len(s.bssid)
        m.bssid, m.rssi_dbm, m.freq_mhz = s.bssid.tolist(), s.rssi_dbm.tolist(), s.freq_mhz.tolist()
        return m

    def truth(i: int):
        m = truth_t()
        m.t_us = int(trace.waypoint_t_ms[i]) * 1000
        m.x_m, m.y_m = (float(v) for v in trace.waypoint_xy_m[i])
        m.floor, m.heading_rad, m.step_count = trace.floor, float("nan"), -1
        m.source = truth_t.SOURCE_WAYPOINT
        return m

    makers = (imu, mag, wifi, truth)
    log = lcm.EventLog(out_path, "w", overwrite=True)
    try:
        for r, i, t in zip(rank[order].tolist(), index[order].tolist(), t_all[order].tolist()):
            log.write_event(t * 1000, CHANNELS[r], makers[r](i).encode())
    finally:
        log.close()
    return len(order)


def import_trace(
    path, out_path, max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S, floor: int | None = None
) -> dict:
    """Read one trace and write its LCM log; return :meth:`Trace.summary` plus ``out`` and ``events``.

    Raises
    ------
    TraceReadError
        The trace is missing or unreadable (or its floor unknown: :class:`TraceHeaderError`).
    OSError
        The log cannot be written.
    """
    trace = read_trace(path, max_wifi_age_s=max_wifi_age_s, floor=floor)
    events = write_lcmlog(trace, out_path)
    summary = trace.summary()
    summary.update(out=os.fspath(out_path), events=events, importer_version=IMPORTER_VERSION)
    return summary


def format_summary(s: dict) -> str:
    """One line for the terminal."""
    m = s["messages"]
    rate = "-" if s["imu_rate_hz"] is None else f"{s['imu_rate_hz']:.0f} Hz"
    return (
        f"{os.path.basename(s['trace'])}: {s['duration_s']:.1f} s, floor {s['floor_name']} "
        f"({s['floor']}), IMU {m['IMU']} ({rate}), MAG {m['MAG']}, WIFI {m['WIFI']} scans / "
        f"{s['wifi_aps_written']} APs ({s['wifi_aps_stale_dropped']} cached dropped), "
        f"TRUTH {m['TRUTH']} waypoints, {s['skipped_lines']} malformed line(s) skipped"
    )


# --- `stridefix import msindoor` -----------------------------------------------------------------


def add_parser(subparsers):
    """Declare ``stridefix import msindoor``."""
    from stridefix_analyzer.datasets.cli import add_output_arguments

    p = subparsers.add_parser(
        "msindoor",
        help="Microsoft Indoor Location Competition 2.0 traces (*.txt)",
        description="Import Indoor Location Competition 2.0 traces: one raw-sensor LCM log "
        "DIR/<trace-stem>.lcmlog per trace, or FILE (-o) for a single trace (IMU, MAG, "
        "WIFI, TRUTH from waypoints), for `stridefixd --input lcmlog:FILE`.",
    )
    p.add_argument("traces", nargs="+", metavar="TRACE.txt", help="trace file(s)")
    add_output_arguments(p)
    p.add_argument(
        "--max-wifi-age-s",
        type=float,
        default=DEFAULT_MAX_WIFI_AGE_S,
        metavar="S",
        help="drop Wi-Fi entries last seen more than S before the scan time "
        f"(cached results; default {DEFAULT_MAX_WIFI_AGE_S:g})",
    )
    p.add_argument(
        "--floor",
        type=int,
        default=None,
        metavar="N",
        help="floor index of the waypoints (default: from the FloorName header)",
    )
    p.add_argument("--json", metavar="FILE", help="also write the summaries as JSON to FILE")
    return p


def run(args) -> int:
    """Import every trace; exit 0, or 2 when a trace was missing/unreadable or output failed."""
    from stridefix_analyzer.datasets.cli import run_imports

    return run_imports(
        args,
        "stridefix import msindoor",
        args.traces,
        lambda trace, out: import_trace(trace, out, args.max_wifi_age_s, args.floor),
        TraceReadError,
        format_summary,
        ("trace", "out", "messages", "skipped_lines", "duration_s", "waypoints"),
        "trace",
    )
