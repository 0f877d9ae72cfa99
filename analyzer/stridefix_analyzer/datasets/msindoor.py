"""The Microsoft Indoor Location Competition 2.0 traces (real Android phone walks) as a data set.

Layout: ``msindoor/<site>/<floor>/path_data_files/*.txt``, docs/datasets.md (one walk per trace; format
in that folder's README), with the floor's ``floor_info.json`` (extent in metres), ``floor_image.png``
and ``geojson_map.json`` beside ``path_data_files``. Walks group per floor folder: each floor is its
own map. No beacon table (beacon positions are learnt by ``stridefix radiomap build``). One trace becomes one raw-sensor LCM log (:mod:`.msindoor_parse` reads it):

=======  ===========  =====================================================================================
channel  type         from
=======  ===========  =====================================================================================
IMU      imu_t        TYPE_ACCELEROMETER (m/s²), with TYPE_GYROSCOPE (rad/s) linearly interpolated to the
                      accelerometer times; seq = 0, 1, ... in time order
MAG      mag_t        TYPE_MAGNETIC_FIELD (µT)
WIFI     wifi_scan_t  one scan = the TYPE_WIFI lines sharing a first-column time; BSSID ``aa:bb:..:ff`` →
                      0xaabb..ff; cached entries (last_seen more than ``max_wifi_age_s`` before the scan)
                      dropped; a BSSID heard twice keeps its freshest entry
BLE      ble_scan_t   TYPE_BEACON: MAC → beacon id, RSSI; readings grouped into windows of
                      ``rawwalk.BLE_WINDOW_S`` (a beacon heard twice in one: its mean RSSI)
TRUTH    truth_t      TYPE_WAYPOINT: x_m, y_m, floor index from the FloorName header (F1 → 0, F2 → 1,
                      B1 → −1, ...), heading NaN, step_count −1, source SOURCE_WAYPOINT
=======  ===========  =====================================================================================

Times: ``t_us`` = the file's unix time [ms] × 1000; events in time order (ties: IMU, MAG, WIFI, BLE, TRUTH).
A missing or unreadable file raises :class:`~.msindoor_parse.TraceReadError` naming it; a FloorName
that cannot be mapped to a floor index raises :class:`~.msindoor_parse.TraceHeaderError` unless the
floor is given.
"""

from __future__ import annotations

import argparse
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stridefix_analyzer.datasets.msindoor_parse import read_trace
from stridefix_analyzer.datasets.protocol import (
    DEFAULT_MAX_WIFI_AGE_S,
    Dataset,
    Defaults,
    FloorPlan,
    PathLike,
    WalkDiscoveryError,
    WalkGroup,
)
from stridefix_analyzer.datasets.rawwalk import RawWalk


def find_floor(floor_dir: PathLike) -> WalkGroup:
    """One floor folder (or its ``path_data_files``) → its group, labelled ``<site>/<floor>``.

    Raises
    ------
    WalkDiscoveryError
        The folder does not exist or holds no ``*.txt`` trace.
    """
    d = Path(floor_dir)
    if not d.is_dir():
        raise WalkDiscoveryError(f"{d}: no such directory")
    if (d / "path_data_files").is_dir():
        d = d / "path_data_files"
    traces = sorted(d.glob("*.txt"))
    if not traces:
        raise WalkDiscoveryError(f"{d}: no *.txt trace files")
    floor = d.parent if d.name == "path_data_files" else d
    plan_dir = traces[0].parent.parent
    return WalkGroup(f"{floor.parent.name}/{floor.name}", tuple(traces), floor, floor_dir=plan_dir)


class MsIndoor(Dataset):
    """Indoor Location Competition 2.0 traces (see the module docstring)."""

    name = "msindoor"
    title = "Microsoft Indoor Location Competition 2.0 traces (*.txt)"
    description = (
        "Import Indoor Location Competition 2.0 traces: one raw-sensor LCM log "
        "DIR/<trace-stem>.lcmlog per trace, or FILE (-o) for a single trace (IMU, MAG, "
        "WIFI, TRUTH from waypoints), for `stridefixd --input lcmlog:FILE`."
    )
    input_metavar = "TRACE.txt"
    input_help = "trace file(s)"
    input_noun = "trace"
    summary_keys = ("trace", "out", "messages", "skipped_lines", "duration_s", "waypoints")
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
    list_order = 0

    def find_walks(self, dirs: Sequence[PathLike]) -> list[WalkGroup]:
        """One group per floor folder."""
        return [find_floor(d) for d in dirs]

    def read(
        self, path: PathLike, *, max_wifi_age_s: float | None = None, floor: int | None = None, **options: Any
    ) -> RawWalk:
        """:func:`~.msindoor_parse.read_trace` (``floor``: override the FloorName header)."""
        age = self.defaults.max_wifi_age_s if max_wifi_age_s is None else max_wifi_age_s
        return read_trace(path, max_wifi_age_s=age, floor=floor, **options)

    def summary(self, raw: RawWalk) -> dict[str, Any]:
        """Counts per channel, skipped lines, duration, waypoints (times on the file's ms clock)."""
        span = raw.time_span_us()
        imu_t_ms = raw.imu["t_us"] // 1000
        dt = np.diff(imu_t_ms)
        span_ms = None if span is None else (span[0] // 1000, span[1] // 1000)
        return {
            "trace": raw.path,
            "site_id": raw.meta["header"].get("SiteID"),
            "floor_name": raw.meta["floor_name"],
            "floor": raw.meta["floor"],
            "messages": {
                "IMU": len(raw.imu),
                "MAG": len(raw.mag),
                "WIFI": raw.n_scans,
                "BLE": raw.n_ble_scans,
                "TRUTH": len(raw.truth),
            },
            "waypoints": len(raw.truth),
            "t_start_us": None if span_ms is None else span_ms[0] * 1000,
            "t_end_us": None if span_ms is None else span_ms[1] * 1000,
            "duration_s": 0.0 if span_ms is None else (span_ms[1] - span_ms[0]) / 1e3,
            "imu_t_first_us": int(imu_t_ms[0]) * 1000 if len(imu_t_ms) else None,
            "imu_t_last_us": int(imu_t_ms[-1]) * 1000 if len(imu_t_ms) else None,
            "imu_rate_hz": float(1e3 / np.median(dt)) if len(dt) else None,
            "imu_max_gap_ms": int(dt.max()) if len(dt) else None,
            **raw.books(),
        }

    def format_summary(self, summary: Mapping[str, Any]) -> str:
        """One line for the terminal."""
        s, m = summary, summary["messages"]
        rate = "-" if s["imu_rate_hz"] is None else f"{s['imu_rate_hz']:.0f} Hz"
        return (
            f"{os.path.basename(s['trace'])}: {s['duration_s']:.1f} s, floor {s['floor_name']} "
            f"({s['floor']}), IMU {m['IMU']} ({rate}), MAG {m['MAG']}, WIFI {m['WIFI']} scans / "
            f"{s['wifi_aps_written']} APs ({s['wifi_aps_stale_dropped']} cached dropped), "
            f"BLE {m['BLE']} scans / {s['ble_readings']} readings of {s['ble_beacons']} beacons, "
            f"TRUTH {m['TRUTH']} waypoints, {s['skipped_lines']} malformed line(s) skipped"
        )

    def floor_plan(self, folder: PathLike) -> FloorPlan | None:
        """``floor_info.json`` (extent), ``floor_image.png`` and ``geojson_map.json`` (when present)."""
        d = Path(folder)
        try:
            info = json.loads((d / "floor_info.json").read_text(encoding="utf-8"))["map_info"]
            width, height = float(info["width"]), float(info["height"])
        except (OSError, ValueError, KeyError, TypeError):
            return None
        geojson = None
        try:
            geojson = json.loads((d / "geojson_map.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            pass
        image = d / "floor_image.png"
        return FloorPlan(width, height, image if image.is_file() else None, geojson)

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        """``--max-wifi-age-s``, ``--floor``."""
        super().add_arguments(parser)
        parser.add_argument(
            "--floor",
            type=int,
            default=None,
            metavar="N",
            help="floor index of the waypoints (default: from the FloorName header)",
        )

    def options(self, args: argparse.Namespace) -> dict[str, Any]:
        return {"max_wifi_age_s": args.max_wifi_age_s, "floor": args.floor}


DATASET = MsIndoor()
