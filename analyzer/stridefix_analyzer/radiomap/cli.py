"""``stridefix radiomap build|show``: the command line of the radio-map builder.

``build`` reads the logs (:mod:`.recordings`; one task per argument on ``--scheduler``, see
:mod:`stridefix_analyzer.parallel`), builds the site (:func:`~.build.build_site`) and writes it; ``show`` checks a site file and prints its summary (and a PNG, :mod:`.show`).
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np
from stridefix import site_t

from stridefix_analyzer.exits import input_error_status
from stridefix_analyzer.io.logread import LogReadError
from stridefix_analyzer.io.sitefile import SiteFileError, read_site, write_site
from stridefix_analyzer.parallel import (
    SchedulerError,
    WorkerFiles,
    add_jobs_argument,
    add_scheduler_argument,
    is_remote,
    task_runner,
)
from stridefix_analyzer.radiomap.assemble import DEFAULT_FLOOR_HEIGHT_M, DEFAULT_MIN_COUNT, site_summary
from stridefix_analyzer.radiomap.build import MODES, build_site
from stridefix_analyzer.radiomap.building import BuildingError, merge_building, read_building
from stridefix_analyzer.radiomap.contexts import ContextMapError, build_context_map, context_map_summary
from stridefix_analyzer.radiomap.floorplan import FloorPlanError
from stridefix_analyzer.radiomap.grid import DEFAULT_CELL_SIZE_M
from stridefix_analyzer.radiomap.placement import DEFAULT_SCAN_DURATION_MS, DEFAULT_STATIC_TOL_M
from stridefix_analyzer.radiomap.recordings import RadioMapInputError, arg_files, load_recordings
from stridefix_analyzer.radiomap.show import format_summary, plot_site


def _float_list(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") from None


def read_beacon_table(path: str, origin: tuple[float, float]) -> dict[str, tuple[float, float, int]]:
    """A beacon table CSV (bleID, Lat, Lon, floor) → name → (x, y, floor) in the frame about origin."""
    import csv

    from stridefix_analyzer.datasets.gsd_convert import project

    try:
        with open(path, encoding="utf-8", newline="") as f:
            rows = list(csv.DictReader(f))
        out = {}
        i = 0
        for i, r in enumerate(rows):  # noqa: B007 - i names the row in the message
            x, y = project([float(r["Lat"])], [float(r["Lon"])], *origin)
            out[r["bleID"]] = (float(x[0]), float(y[0]), int(r["floor"]))
    except OSError as exc:
        raise RadioMapInputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except (KeyError, ValueError) as exc:
        raise RadioMapInputError(
            f"{path}: row {i + 2}: bad field {exc} (needs bleID,Lat,Lon,floor)"
        ) from None
    return out


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare ``radiomap build`` and ``radiomap show``."""
    p = subparsers.add_parser(
        "radiomap",
        help="build a site file (radio map) from logs; show one",
        description="Radio maps: build a site file from Wi-Fi scans with "
        "ground truth, or summarise/plot a site file.",
    )
    sub = p.add_subparsers(dest="radiomap_command", metavar="ACTION", required=True)
    b = sub.add_parser(
        "build",
        help="site file from LCM logs with WIFI + TRUTH",
        description="Build a site file from LCM logs with WIFI and TRUTH. An argument 'a,b' is "
        "one recording of both files; an argument holding WIFI and TRUTH is a "
        "recording; the other arguments (e.g. firmware log + truth log) are merged "
        "into one recording.",
    )
    b.add_argument("logs", nargs="+", metavar="LOG")
    b.add_argument("--out", required=True, metavar="SITE.sfsite", help="site file to write")
    b.add_argument(
        "--mode",
        choices=MODES,
        default="auto",
        help="survey: one RP per surveyed point; walk: RPs on a grid; auto: survey "
        "when the truth is static during most scans, repeated per spot (default)",
    )
    b.add_argument(
        "--cell-size-m",
        type=float,
        default=DEFAULT_CELL_SIZE_M,
        help=f"grid cell of walk mode [m] (default {DEFAULT_CELL_SIZE_M:g})",
    )
    b.add_argument("--name", default="", help="site name (default: the output file's stem)")
    b.add_argument(
        "--map-rotation-deg",
        type=float,
        default=0.0,
        help="map frame = magnetic east-north turned CCW by this angle [deg]",
    )
    g = b.add_mutually_exclusive_group()
    g.add_argument(
        "--floor-height-m",
        type=float,
        default=DEFAULT_FLOOR_HEIGHT_M,
        help=f"storey height: floor f at f × this [m] (default {DEFAULT_FLOOR_HEIGHT_M:g})",
    )
    g.add_argument(
        "--floor-heights-m",
        type=_float_list,
        default=None,
        metavar="H0,H1,...",
        help="walking-surface height of each floor from the lowest [m]",
    )
    b.add_argument(
        "--lowest-floor",
        type=int,
        default=None,
        help="lowest floor index (default: the lowest with reference points)",
    )
    b.add_argument(
        "--min-count",
        type=int,
        default=DEFAULT_MIN_COUNT,
        help=f"drop (RP, AP) entries heard in fewer scans (default {DEFAULT_MIN_COUNT})",
    )
    b.add_argument(
        "--origin-deg",
        type=_float_list,
        default=None,
        metavar="LAT,LON",
        help="geo-reference of the map origin (sets has_geo)",
    )
    b.add_argument(
        "--scan-duration-ms",
        type=float,
        default=DEFAULT_SCAN_DURATION_MS,
        help="truth must stay put this long after a scan's start for it to count as "
        "static [ms] (default 0: the samples around the start)",
    )
    b.add_argument(
        "--static-tol-m",
        type=float,
        default=DEFAULT_STATIC_TOL_M,
        help=f"truth within this distance counts as the same spot [m] (default {DEFAULT_STATIC_TOL_M:g})",
    )
    b.add_argument(
        "--building",
        default=None,
        metavar="FILE",
        help="building description (building.toml, docs/building.md): geo-reference, BLE model, "
        "walls, ports and beacons merged into the site; with [[building]] entries also the "
        "multi-scheme controller's context map",
    )
    b.add_argument(
        "--beacon-table",
        default=None,
        metavar="CSV",
        help="beacon positions (gsd's BLE_Locations.csv: bleID,Lat,Lon,floor), projected about "
        "--origin-deg; each name is matched to the MAC loudest near it in the walks",
    )
    b.add_argument(
        "--floor-plan",
        default=None,
        metavar="GEOJSON",
        help="msindoor floor plan (geojson_map.json): its outline and rooms become walls, opened "
        "(a door's width) where the walks' truth crosses them; sets the geo-reference",
    )
    b.add_argument(
        "--floor-info",
        default=None,
        metavar="JSON",
        help="the plan's floor_info.json (map width/height [m]; default: the one beside --floor-plan)",
    )
    b.add_argument(
        "--plan-floor",
        type=int,
        default=None,
        metavar="N",
        help="floor index of the plan's walls (default: the walks' floor, when they are on one)",
    )
    b.add_argument(
        "--min-room-area-m2",
        type=float,
        default=0.0,
        metavar="A",
        help="rooms of the plan smaller than this are no walls (default 0: every room)",
    )
    add_scheduler_argument(b, "serial")
    add_jobs_argument(b, "processes of --scheduler processes or local", dest="workers")
    s = sub.add_parser(
        "show",
        help="summary (and PNG) of a site file",
        description="Check a site file and print its summary; --png plots the "
        "reference points per floor coloured by APs heard, with the walls, "
        "beacons (ids) and ports of the site.",
    )
    s.add_argument("site", metavar="SITE.sfsite")
    s.add_argument(
        "--png", default=None, metavar="PATH", help="write a PNG of the floor plan, RPs, beacons and ports"
    )
    return p


def add_floor_plan(site: site_t, recordings: list, args: argparse.Namespace) -> dict:
    """Walls and geo-reference of ``--floor-plan`` written into ``site``; returns the plan report."""
    from stridefix_analyzer.io.sitefile import set_counts
    from stridefix_analyzer.radiomap.floorplan import load_plan, site_plan

    plan = load_plan(args.floor_plan, args.floor_info)
    xy = [np.column_stack([r.truth["x_m"], r.truth["y_m"]]) for r in recordings]
    floors = [np.asarray(r.truth["floor"], np.int64) for r in recordings]
    seen = sorted({int(f) for fl in floors for f in fl})
    floor = args.plan_floor
    if floor is None:
        if len(seen) != 1:
            raise RadioMapInputError(f"--floor-plan: the walks are on floors {seen}: give --plan-floor N")
        floor = seen[0]
    on = [fl == floor for fl in floors]
    fields, report = site_plan(
        plan,
        [p[m] for p, m in zip(xy, on)],
        [f[m] for f, m in zip(floors, on)],
        floor,
        min_room_area_m2=args.min_room_area_m2,
    )
    for k, v in fields.items():
        setattr(site, k, v)
    set_counts(site)
    site.source = f"{site.source}; floor plan {os.path.basename(args.floor_plan)}"
    return report


def run_build(args: argparse.Namespace) -> tuple[site_t, dict]:
    """Build and write the site of ``args`` (the ``build`` options); return (site, summary)."""
    if args.origin_deg is not None and len(args.origin_deg) != 2:
        raise RadioMapInputError("--origin-deg needs LAT,LON")
    table = None
    if getattr(args, "beacon_table", None):
        if args.origin_deg is None:
            raise RadioMapInputError("--beacon-table needs --origin-deg LAT,LON (the frame's origin)")
        table = read_beacon_table(args.beacon_table, tuple(args.origin_deg))
    logs, scheduler = list(args.logs), getattr(args, "scheduler", None)
    if is_remote(scheduler):  # a remote worker's working folder is not ours
        logs = [",".join(os.path.abspath(f) for f in arg_files(a)) for a in logs]
    files = WorkerFiles(read=[f for a in logs for f in arg_files(a)])
    with task_runner(scheduler, getattr(args, "workers", 2), files) as runner:
        recordings = load_recordings(logs, runner)
    name = args.name or os.path.splitext(os.path.basename(args.out))[0]
    site, summary = build_site(
        recordings,
        mode=args.mode,
        cell_size_m=args.cell_size_m,
        min_count=args.min_count,
        name=name,
        map_rotation_deg=args.map_rotation_deg,
        floor_height_m=args.floor_height_m,
        floor_heights_m=args.floor_heights_m,
        lowest_floor=args.lowest_floor,
        origin_deg=tuple(args.origin_deg) if args.origin_deg else None,
        scan_duration_ms=args.scan_duration_ms,
        static_tol_m=args.static_tol_m,
        beacon_table=table,
    )
    if getattr(args, "floor_plan", None):
        summary["floor_plan"] = add_floor_plan(site, recordings, args)
    if getattr(args, "building", None):
        building = read_building(args.building)
        summary["building"] = merge_building(site, building, os.path.basename(args.building))
        if building.buildings:
            from stridefix_analyzer.radiomap.beacons import place_readings

            summary["context_map"] = build_context_map(site, building, place_readings(recordings))
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    summary["bytes"] = write_site(args.out, site)
    return site, summary


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix radiomap``; returns the exit status."""
    prog = f"stridefix radiomap {args.radiomap_command}"
    try:
        if args.radiomap_command == "build":
            _, summary = run_build(args)
            print(format_summary(summary))
            print(f"wrote {args.out} ({summary['bytes']} bytes)")
        else:
            site = read_site(args.site)
            shown = site_summary(site)
            if site.n_contexts:
                shown["context_map"] = context_map_summary(site)
            print(format_summary(shown))
            if args.png:
                plot_site(site, args.png)
                print(f"wrote {args.png}")
    except (
        LogReadError,
        RadioMapInputError,
        SiteFileError,
        BuildingError,
        FloorPlanError,
        ContextMapError,
        SchedulerError,
    ) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    return 0
