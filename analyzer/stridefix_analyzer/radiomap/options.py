"""The options of a site build (:class:`~.make.SiteOptions`) as both commands that build one declare
them: ``stridefix radiomap build`` and ``stridefix site``. Declarations only."""

from __future__ import annotations

import argparse

from stridefix_analyzer.radiomap.assemble import DEFAULT_FLOOR_HEIGHT_M
from stridefix_analyzer.radiomap.build import MODES
from stridefix_analyzer.radiomap.grid import DEFAULT_CELL_SIZE_M
from stridefix_analyzer.radiomap.placement import DEFAULT_SCAN_DURATION_MS, DEFAULT_STATIC_TOL_M


def float_list(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") from None


def add_site_options(b: argparse.ArgumentParser, *, min_count: int) -> None:
    """Declare every :class:`~.make.SiteOptions` field but ``learn_beacons`` (each command's own)."""
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
        type=float_list,
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
        default=min_count,
        help=f"drop (RP, AP) entries heard in fewer scans (default {min_count})",
    )
    b.add_argument(
        "--origin-deg",
        type=float_list,
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
