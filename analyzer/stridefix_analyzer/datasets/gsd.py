"""GetSensorData logfiles (the IPIN competition Track 3 format: real Android phone walks) as a data set.

Layout: ``gsd/*.txt``, docs/datasets.md (one walk per logfile; format in that folder's README and in each
file's ``%`` header) with ``BLE_Locations.csv`` (the building's beacons) beside them. Walks group per
folder, all read about one origin (the first POSI of the folder's first log) so they share one frame,
and are split by the building of their ground truth once read. One logfile becomes one raw-sensor LCM
log (:mod:`.gsd_parse` reads the records, :mod:`.gsd_convert` aligns the clocks):

=======  ===========  =====================================================================================
channel  type         from
=======  ===========  =====================================================================================
IMU      imu_t        ``ACCE`` (m/s²), with ``GYRO`` (rad/s) linearly interpolated to the accelerometer
                      times; timed by the sensor clock aligned to the app clock
MAG      mag_t        ``MAGN`` (µT)
BARO     baro_t       ``PRES``, converted to Pa from the unit the header declares; temperature NaN
GNSS     gnss_t       ``GNSS``: latitude, longitude, altitude, accuracy; repeated fixes dropped (counted)
WIFI     wifi_scan_t  one scan = the ``WIFI`` records within :data:`~.gsd_convert.WIFI_GROUP_S` of the
                      scan's first one; cached entries (older than ``max_wifi_age_s``) dropped
BLE      ble_scan_t   ``BLE4`` (iBeacon, Eddystone): MAC → beacon id, RSSI; windows of
                      ``rawwalk.BLE_WINDOW_S`` on the app clock
TRUTH    truth_t      ``POSI``: latitude/longitude → local metres, x east and y north, about an origin;
                      floor = the floor id; heading NaN, step_count −1, source SOURCE_WAYPOINT
=======  ===========  =====================================================================================

Events in time order (ties: IMU, MAG, BARO, GNSS, WIFI, BLE, TRUTH). A missing or unreadable file raises
:class:`~.gsd_parse.LogReadError` naming it; an unknown pressure unit
:class:`~.gsd_parse.LogHeaderError`.
"""

from __future__ import annotations

import argparse
import csv
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stridefix_analyzer.datasets.gsd_convert import parse_origin, to_rawwalk
from stridefix_analyzer.datasets.gsd_parse import MAX_LINE_WARNINGS, parse_log
from stridefix_analyzer.datasets.protocol import (
    DEFAULT_MAX_WIFI_AGE_S,
    Dataset,
    Defaults,
    PathLike,
    WalkDiscoveryError,
    WalkGroup,
    add_max_wifi_age_argument,
)
from stridefix_analyzer.datasets.rawwalk import RawWalk
from stridefix_analyzer.io.logread import Table

BEACON_FILE = "BLE_Locations.csv"


def first_posi(path: PathLike) -> tuple[float, float] | None:
    """The first ``POSI`` latitude/longitude of a logfile [deg]: the common origin of the local metres
    of every walk of its folder (the importer's default origin is per file)."""
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("POSI;"):
                p = line.split(";")
                try:
                    return float(p[3]), float(p[4])
                except (IndexError, ValueError):
                    continue
    return None


def _origin_arg(text: str) -> tuple[float, float]:
    try:
        return parse_origin(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


class Gsd(Dataset):
    """GetSensorData / IPIN Track 3 logfiles (see the module docstring)."""

    name = "gsd"
    title = "GetSensorData / IPIN Track 3 logfiles (*.txt)"
    description = (
        "Import GetSensorData logfiles (IPIN competition Track 3 format): one raw-sensor "
        "LCM log per logfile (IMU, MAG, BARO, GNSS, WIFI, TRUTH from the POSI records in "
        "local metres, x east, y north, about --origin), for "
        "`stridefixd --input lcmlog:FILE`."
    )
    input_metavar = "LOGFILE.txt"
    input_help = "logfile(s)"
    input_noun = "logfile"
    summary_keys = (
        "trace",
        "out",
        "messages",
        "skipped_lines",
        "duration_s",
        "waypoints",
        "building_id",
        "floors",
        "origin",
    )
    version = 1
    defaults = Defaults(max_wifi_age_s=DEFAULT_MAX_WIFI_AGE_S)
    # The magnetometer records are Android's TYPE_MAGNETIC_FIELD, which the OS has already corrected
    # for hard iron (TYPE_MAGNETIC_FIELD_UNCALIBRATED is the raw one): a second online fit (sf_magcal)
    # only adds error. Measured with realbench (first fix / true start, pdr_only mean): site1/F2
    # 6.57 -> 6.38 / 4.09 -> 3.77 m, site2/F3 20.50 -> 20.39 / 3.89 -> 3.65 m, gsd 8.60 -> 7.58 /
    # 6.54 -> 4.82 m.
    # An Android phone's sensor frame has y along the screen's long side, towards its top: the way a
    # phone held in front of the walker (the hand-held walks of this set) points. That is the prior of
    # the walking direction (heading.mount_offset_deg = 90: y is 90 deg CCW from x) until the gait has
    # taught the estimator the angle online (sf_heading.h); with 0 the first steps of every walk went
    # 90 deg off and the map rotation learned on other walks could not absorb both.
    firmware_sets = ("magcal.enable=0", "heading.mount_offset_deg=90")
    list_order = 1

    def find_walks(self, dirs: Sequence[PathLike]) -> list[WalkGroup]:
        """One group per DIR (or log file), read about the first POSI of its first log."""
        groups = []
        for d in map(Path, dirs):
            if d.is_file():
                traces = [d]
            elif d.is_dir():
                traces = sorted(p for p in d.glob("*.txt") if p.name.lower() != "readme.txt")
            else:
                raise WalkDiscoveryError(f"{d}: no such file or directory")
            if not traces:
                raise WalkDiscoveryError(f"{d}: no *.txt GetSensorData logs")
            origin = first_posi(traces[0])
            label = d.stem if d.is_file() else d.name
            folder = d.parent if d.is_file() else d
            options = {"origin": list(origin)} if origin else {}
            groups.append(WalkGroup(label, tuple(traces), folder, options=options))
        return groups

    def regroup(
        self, group: WalkGroup, summaries: Sequence[Mapping[str, Any] | None]
    ) -> list[tuple[str, list[int]]]:
        """Split by the building of the ground truth; walks without one stay in the folder's group."""
        by: dict[str, list[int]] = {}
        for i, s in enumerate(summaries):
            b = (s or {}).get("building_id")
            by.setdefault(group.label if b is None else f"{group.label}/building {b}", []).append(i)
        return list(by.items())

    def read(
        self,
        path: PathLike,
        *,
        max_wifi_age_s: float | None = None,
        origin: Sequence[float] | None = None,
        max_line_warnings: int = MAX_LINE_WARNINGS,
        **options: Any,
    ) -> RawWalk:
        """One logfile; ``origin`` (lat, lon) [deg] of the truth's metres (default: its first POSI)."""
        if options:
            raise TypeError(f"gsd: unknown read option(s) {sorted(options)}")
        age = self.defaults.max_wifi_age_s if max_wifi_age_s is None else max_wifi_age_s
        o = None if origin is None else (float(origin[0]), float(origin[1]))
        return to_rawwalk(parse_log(path, max_line_warnings), o, age)

    def summary(self, raw: RawWalk) -> dict[str, Any]:
        """Counts per channel, rates, origin, building, skipped lines."""
        span = raw.time_span_us()

        def rate(t: np.ndarray) -> float | None:
            dt = np.diff(t)
            return float(1e6 / np.median(dt)) if len(dt) else None

        imu_t, truth_t = raw.imu["t_us"], raw.truth["t_us"]
        dt = np.diff(imu_t)
        floors = sorted(set(raw.truth["floor"].tolist()))
        m = raw.meta
        return {
            "trace": raw.path,
            "format": "gsd",
            "device": dict(m["header"]),
            "building_id": m["building_ids"][0] if len(m["building_ids"]) == 1 else None,
            "building_ids": list(m["building_ids"]),
            "floors": floors,
            "floor": floors[0] if len(floors) == 1 else None,
            "origin": None
            if m["origin"] is None
            else {"lat_deg": m["origin"][0], "lon_deg": m["origin"][1], "source": m["origin_source"]},
            "projection": "local tangent plane, WGS-84 radii at the origin; x east, y north [m]",
            "messages": {
                "IMU": len(raw.imu),
                "MAG": len(raw.mag),
                "BARO": len(raw.baro),
                "GNSS": len(raw.gnss),
                "WIFI": raw.n_scans,
                "BLE": raw.n_ble_scans,
                "TRUTH": len(raw.truth),
            },
            "waypoints": len(raw.truth),
            "t_start_us": None if span is None else span[0],
            "t_end_us": None if span is None else span[1],
            "duration_s": 0.0 if span is None else (span[1] - span[0]) / 1e6,
            "truth_t_first_us": int(truth_t[0]) if len(truth_t) else None,
            "truth_t_last_us": int(truth_t[-1]) if len(truth_t) else None,
            "imu_t_first_us": int(imu_t[0]) if len(imu_t) else None,
            "imu_t_last_us": int(imu_t[-1]) if len(imu_t) else None,
            "imu_rate_hz": rate(imu_t),
            "imu_max_gap_ms": float(dt.max()) / 1e3 if len(dt) else None,
            "mag_rate_hz": rate(raw.mag["t_us"]),
            "baro_rate_hz": rate(raw.baro["t_us"]),
            **raw.books(),
        }

    def format_summary(self, summary: Mapping[str, Any]) -> str:
        """One line for the terminal."""
        s, m = summary, summary["messages"]
        rate = "-" if s["imu_rate_hz"] is None else f"{s['imu_rate_hz']:.0f} Hz"
        o = s["origin"]
        origin = "-" if o is None else f"{o['lat_deg']:.9f},{o['lon_deg']:.9f} ({o['source']})"
        floors = ",".join(str(f) for f in s["floors"]) or "-"
        return (
            f"{os.path.basename(s['trace'])}: {s['duration_s']:.1f} s, building "
            f"{s['building_id'] or ','.join(s['building_ids']) or '-'}, floor(s) {floors}, "
            f"IMU {m['IMU']} ({rate}), MAG {m['MAG']}, BARO {m['BARO']}, GNSS {m['GNSS']}, "
            f"WIFI {m['WIFI']} scans / {s['wifi_aps_written']} APs "
            f"({s['wifi_aps_stale_dropped']} cached dropped), "
            f"BLE {m['BLE']} scans / {s['ble_readings']} readings of {s['ble_beacons']} beacons, "
            f"TRUTH {m['TRUTH']} POSI, "
            f"origin {origin}, {s['skipped_lines']} malformed line(s) skipped"
        )

    def beacons(self, folder: PathLike) -> Table | None:
        """``BLE_Locations.csv``: ``id``, ``lat_deg``, ``lon_deg``, ``floor`` per beacon; None without it."""
        path = Path(folder) / BEACON_FILE
        try:
            with open(path, encoding="utf-8", newline="") as f:
                rows = [r for r in csv.DictReader(f)]
            return Table(
                {
                    "id": np.array([r["bleID"] for r in rows], dtype=object),
                    "lat_deg": np.array([float(r["Lat"]) for r in rows]),
                    "lon_deg": np.array([float(r["Lon"]) for r in rows]),
                    "floor": np.array([int(r["floor"]) for r in rows], dtype=np.int64),
                }
            )
        except (OSError, KeyError, ValueError):
            return None

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        """``--origin``, ``--max-wifi-age-s``."""
        parser.add_argument(
            "--origin",
            type=_origin_arg,
            default=None,
            metavar="LAT,LON",
            help="origin of the truth's local metres [deg] (default: the file's first POSI; "
            "give one origin for all walks of a building; a negative latitude needs "
            "the = form: --origin=-33.9,151.2)",
        )
        add_max_wifi_age_argument(parser, self.defaults)

    def options(self, args: argparse.Namespace) -> dict[str, Any]:
        return {"origin": args.origin, "max_wifi_age_s": args.max_wifi_age_s}


DATASET = Gsd()
