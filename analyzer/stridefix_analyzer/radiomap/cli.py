"""``stridefix radiomap build|show``: the command line of the radio-map builder.

``build`` declares the options of :class:`~.make.SiteOptions` and calls :func:`~.make.make_site` (the
logs read on ``--scheduler``, the site built and written); ``show`` checks a site file and prints its
summary (and a PNG, :mod:`.show`). This module only declares and dispatches.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys

from stridefix_common.exits import input_error_status

from stridefix_analyzer.io.sitefile import read_site
from stridefix_analyzer.parallel import (
    add_jobs_argument,
    add_scheduler_argument,
)
from stridefix_analyzer.radiomap.assemble import DEFAULT_FLOOR_HEIGHT_M, DEFAULT_MIN_COUNT, site_summary
from stridefix_analyzer.radiomap.build import MODES
from stridefix_analyzer.radiomap.contexts import context_map_summary
from stridefix_analyzer.radiomap.grid import DEFAULT_CELL_SIZE_M
from stridefix_analyzer.radiomap.make import INPUT_ERRORS, SiteOptions, make_site
from stridefix_analyzer.radiomap.placement import DEFAULT_SCAN_DURATION_MS, DEFAULT_STATIC_TOL_M
from stridefix_analyzer.radiomap.show import format_summary, plot_site


def _float_list(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") from None


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


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix radiomap``; returns the exit status."""
    prog = f"stridefix radiomap {args.radiomap_command}"
    try:
        if args.radiomap_command == "build":
            _, summary = make_site(
                args.logs,
                args.out,
                SiteOptions(**{f.name: getattr(args, f.name) for f in dataclasses.fields(SiteOptions)}),
                scheduler=args.scheduler,
                workers=args.workers,
            )
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
    except INPUT_ERRORS as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    return 0
