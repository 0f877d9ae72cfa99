"""``stridefix-lab realbench``: the command line of the real-data benchmarks (it only declares arguments and
calls the benchmark modules).

``fusion`` (the default: ``stridefix-lab realbench --format NAME DIR... --out results.json``): every fusion
scheme, leave one walk out (:mod:`.fusion`); ``--format`` is any registered data set.
``pdr-distance``: step detection + Weinberg length against the distance walked (:mod:`.pdr_distance`).
``crowd-map``: fusion's folds replayed on the truth-built and on a crowd-built site (:mod:`.crowdmap`).
Exit status: 0 done, 1 nothing could be scored or a walk failed, 2 bad usage or unreadable input, 3 not
one walk imported (every file empty, binary or not of the format).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path
from typing import Any

from stridefix_analyzer import console, datasets
from stridefix_analyzer.datasets.protocol import DEFAULT_MAX_WIFI_AGE_S, seconds_arg
from stridefix_analyzer.firmware import add_stridefixd_argument
from stridefix_analyzer.io.logread import LogReadError
from stridefix_analyzer.parallel import SchedulerError, add_jobs_argument, add_scheduler_argument
from stridefix_analyzer.radiomap.strides import DEFAULT_MIN_SEGMENT_M
from stridefix_common.exits import input_error_status

from stridefix_lab.realbench import tuning
from stridefix_lab.realbench.fold import DEFAULT_MIN_COUNT
from stridefix_lab.realbench.fusion import DEFAULT_CELL_SIZE_M, FusionConfig, run_fusion
from stridefix_lab.realbench.pdr_distance import (
    DEFAULT_OUT,
    JSON_FILE,
    PNG_FILE,
    format_table,
    missed_targets,
    run_pdr_distance,
)
from stridefix_lab.realbench.sitecontent import ContentOptions
from stridefix_lab.realbench.summary import format_tables
from stridefix_lab.realbench.walks import RealbenchError

BENCHES = ("fusion", "pdr-distance", "crowd-map")


def with_default_bench(argv: list[str]) -> list[str]:
    """``stridefix-lab realbench --format ...`` means ``stridefix-lab realbench fusion --format ...``:
    insert the default benchmark when the word after ``realbench`` names none (and is no help)."""
    argv = list(argv)
    if argv and argv[0] == "realbench" and (len(argv) == 1 or argv[1] not in (*BENCHES, "-h", "--help")):
        argv.insert(1, "fusion")
    return argv


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Declare ``stridefix-lab realbench`` and its benchmarks (``fusion`` is the default)."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "realbench",
        help="benchmarks of stridefixd on real public data (msindoor, gsd)",
        description="Benchmarks of the real firmware on real data sets. Without a benchmark name "
        "the fusion benchmark runs: stridefix-lab realbench --format msindoor DIR [DIR...] "
        "--out results.json",
    )
    sub = p.add_subparsers(dest="bench", metavar="BENCH", required=True)
    add_fusion_parser(sub)
    add_crowd_map_parser(sub)
    d = sub.add_parser(
        "pdr-distance",
        help="segment distance from steps + Weinberg length, K leave-one-walk-out",
        description="For every trace of a floor: import, replay through stridefixd, and compare "
        "the Weinberg distance (K calibrated leave-one-walk-out) between consecutive "
        "waypoints with the true straight-line distance. Writes "
        f"DIR/{JSON_FILE} and DIR/{PNG_FILE}.",
    )
    d.add_argument(
        "--floor",
        required=True,
        metavar="DIR",
        help="floor folder, e.g. ../shared/data/msindoor/site1/F2[/path_data_files]",
    )
    add_stridefixd_argument(d)
    d.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help=f"output and cache directory (default: {DEFAULT_OUT}/<site>-<floor>)",
    )
    d.add_argument(
        "--limit", type=int, default=None, metavar="N", help="only the first N traces (sorted by name)"
    )
    d.add_argument(
        "--min-segment-m",
        type=float,
        default=DEFAULT_MIN_SEGMENT_M,
        metavar="M",
        help=f"exclude shorter segments (default {DEFAULT_MIN_SEGMENT_M:g})",
    )
    _add_max_wifi_age(d)
    _add_workers(d, help_text="walks prepared in parallel: processes of --scheduler processes or local")
    d.add_argument("--reimport", action="store_true", help="ignore the cached imported logs")
    _add_quiet(d)
    d.set_defaults(_bench=_run_pdr_distance_cli)
    return p


def _run_pdr_distance_cli(args: argparse.Namespace) -> int:
    try:
        doc = run_pdr_distance(
            args.floor,
            args.stridefixd,
            args.out,
            args.limit,
            args.min_segment_m,
            args.max_wifi_age_s,
            args.jobs,
            args.reimport,
            progress=not console.quiet(),
            scheduler=args.scheduler,
        )
    except (
        RealbenchError,
        LogReadError,
        SchedulerError,
    ) as exc:  # LogReadError: e.g. a stale stridefixd build
        print(f"stridefix-lab realbench: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    print(format_table(doc))
    print(
        f"wrote {os.path.join(doc['out_dir'], JSON_FILE)} and {os.path.join(doc['out_dir'], PNG_FILE)} "
        f"({doc['run_s']:.1f} s)"
    )
    if not doc["segments"]["scored"]:
        return 1
    missed = missed_targets(doc)
    for line in missed:  # the same contract as `stridefix-lab bench`: exit 1 when a target is missed
        print(f"TARGET MISSED: {line}")
    return 1 if missed else 0


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix-lab realbench``; its own ``-q`` is the global ``stridefix -q``."""
    if getattr(args, "quiet", False):
        console.set_level(console.QUIET)
    return int(args._bench(args) or 0)


def add_fusion_parser(sub: Any) -> None:
    """Declare ``stridefix-lab realbench [fusion]``."""
    d = sub.add_parser(
        "fusion",
        help="all fusion schemes on real walks, leave one walk out (default benchmark)",
        description="Leave one walk out per floor (msindoor) or building (gsd): build the site "
        "(walk-mode radio map, floors, map rotation) and Weinberg K from the other "
        "walks, replay the held-out walk through stridefixd --site and score every "
        "fusion scheme at its ground-truth times. Writes results.json, an HTML report next "
        "to it, and per-walk work files under its folder.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    d.add_argument(
        "dirs",
        nargs="+",
        metavar="DIR",
        help="msindoor: floor folders (site1/F2 or its path_data_files); gsd: folders "
        "of GetSensorData logs (or log files)",
    )
    d.add_argument("--format", required=True, choices=datasets.names(), help="data set format")
    d.add_argument("--out", required=True, metavar="results.json", help="JSON results file")
    add_stridefixd_argument(d)
    d.add_argument(
        "--limit",
        type=int,
        default=None,
        metavar="N",
        help="only the first N walks of each group (sorted by name)",
    )
    _add_workers(d)
    d.add_argument(
        "--true-start", action="store_true", help="also run every walk truth-initialised (labelled as such)"
    )
    d.add_argument("--cell-size-m", type=float, default=DEFAULT_CELL_SIZE_M, help="radio-map grid cell [m]")
    d.add_argument(
        "--min-count",
        type=int,
        default=DEFAULT_MIN_COUNT,
        help="radio map: drop (cell, AP) entries heard in fewer scans",
    )
    _add_max_wifi_age(d)
    d.add_argument(
        "--set",
        dest="param_sets",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="firmware parameter for every replay (stridefixd --set; repeatable): what-if "
        "runs; recorded in results.json",
    )
    d.add_argument(
        "--cache", default=None, metavar="DIR", help="import cache (default: <folder of results.json>/cache)"
    )
    d.add_argument("--reimport", action="store_true", help="ignore the cached imports")
    d.add_argument(
        "--no-floor-plan",
        action="store_true",
        help="fold sites without the data set's floor plan (walls opened where the training walks cross)",
    )
    d.add_argument(
        "--no-beacons",
        action="store_true",
        help="fold sites without BLE beacons and path-loss model (learnt from the training walks)",
    )
    d.add_argument(
        "--learn-beacons",
        action="store_true",
        help="a data set without a beacon table (msindoor): place its beacons from the training walks and "
        "use them (off by default: positions from interpolated truth err by metres)",
    )
    d.add_argument(
        "--no-gnss",
        action="store_true",
        help="fold sites without a geo-reference, so no GNSS fix is used",
    )
    d.add_argument(
        "--no-controller",
        action="store_true",
        help="fold sites without a context map, so the multi-scheme controller does not run (and its "
        "scheme is not chosen on the training walks)",
    )
    d.add_argument("--no-report", action="store_true", help="skip the HTML report")
    _add_quiet(d)
    d.set_defaults(_bench=_run_fusion_cli)


def _add_workers(
    d: argparse.ArgumentParser,
    help_text: str = "worker processes of --scheduler processes or local (a scheduler address has its own)",
) -> None:
    """``--jobs``/``--workers`` and ``--scheduler`` (default: local processes) of the realbench commands."""
    add_jobs_argument(d, help_text)
    add_scheduler_argument(d, "processes")


def _add_quiet(d: argparse.ArgumentParser) -> None:
    d.add_argument(
        "--quiet", "-q", action="store_true", help="no progress on stderr (= stridefix -q realbench)"
    )


def _add_max_wifi_age(d: argparse.ArgumentParser) -> None:
    """``--max-wifi-age-s S``: every data set's default (the import command's too)."""
    d.add_argument(
        "--max-wifi-age-s",
        type=seconds_arg,
        default=DEFAULT_MAX_WIFI_AGE_S,
        metavar="S",
        help=f"importer: drop cached Wi-Fi entries older than S seconds (default {DEFAULT_MAX_WIFI_AGE_S:g})",
    )


def _run_fusion_cli(args: argparse.Namespace) -> int:
    try:
        cfg = FusionConfig(
            fmt=args.format,
            dirs=args.dirs,
            out_json=Path(args.out),
            stridefixd=args.stridefixd,
            limit=args.limit,
            jobs=args.jobs,
            scheduler=args.scheduler,
            reimport=args.reimport,
            true_start=args.true_start,
            max_wifi_age_s=args.max_wifi_age_s,
            cell_size_m=args.cell_size_m,
            min_count=args.min_count,
            cache_dir=args.cache,
            report=not args.no_report,
            quiet=console.quiet(),
            param_sets=args.param_sets,
            content=ContentOptions(
                floor_plan=not args.no_floor_plan,
                beacons=not args.no_beacons,
                gnss=not args.no_gnss,
                learn_beacons=args.learn_beacons,
                controller=not args.no_controller,
            ),
        )
        doc = run_fusion(cfg)
    except (
        RealbenchError,
        LogReadError,
        SchedulerError,
    ) as exc:  # LogReadError: e.g. a stale stridefixd build
        print(f"stridefix-lab realbench: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    print(format_tables(doc, tuning.axes(args.param_sets)))
    extra = f" and {doc['report']}" if doc.get("report") else ""
    print(
        f"wrote {args.out}{extra} ({doc['run_s']['total']:.1f} s: prepare "
        f"{doc['run_s']['prepare']:.1f} s, folds {doc['run_s']['folds']:.1f} s)"
    )
    scored = sum(s["n"] for g in doc["groups"] for s in g["summary"]["schemes"].values())
    failed = failed_walks(doc)
    if failed:
        # the results.json is written all the same; a failed walk is a failed run, never a quiet gap
        names = ", ".join(f"{w} ({why})" for w, why in failed[:5]) + (" ..." if len(failed) > 5 else "")
        print(f"stridefix-lab realbench: error: {len(failed)} walk(s) failed: {names}", file=sys.stderr)
    return 0 if scored and not failed else 1


def failed_walks(doc: dict) -> list[tuple[str, str]]:
    """(walk, why) of every walk that could not be prepared or scored, in the groups' order."""
    return [
        (e["walk"], e["error"])
        for g in doc["groups"]
        for e in [*g.get("failed", []), *g.get("fold_errors", [])]
    ]


def add_crowd_map_parser(sub: Any) -> None:
    """Declare ``stridefix-lab realbench crowd-map``."""
    from stridefix_analyzer.crowd.graph_solve import SOLVERS as GRAPH_SOLVERS

    d = sub.add_parser(
        "crowd-map",
        help="fix error on a crowd-built radio map (anchors only) next to the truth-built one",
        description="The walks and leave-one-walk-out folds of realbench fusion; per fold two sites "
        "from the training walks: the truth-built one (as fusion builds it) and the crowd-built one, "
        "identical except that each training walk's scans sit at its graph-solved positions (anchors "
        "every K-th waypoint + its steps). The held-out walk is replayed on both and scored. Writes "
        "results.json and per-fold work folders beside it.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    d.add_argument("dirs", nargs="+", metavar="DIR", help="floor folders (msindoor: site1/F2)")
    d.add_argument("--format", required=True, choices=datasets.names(), help="data set format")
    d.add_argument("--out", required=True, metavar="results.json", help="JSON results file")
    add_stridefixd_argument(d)
    d.add_argument("--anchors", default="every:4", metavar="every:K", help="anchored waypoints per walk")
    d.add_argument("--solver", choices=GRAPH_SOLVERS, default="auto", help="graph solver")
    d.add_argument(
        "--max-sigma-m",
        type=float,
        default=math.inf,
        metavar="M",
        help="crowd map: leave out scans whose solved position has a posterior sigma above M metres",
    )
    d.add_argument(
        "--limit", type=int, default=None, metavar="N", help="only the first N walks of each group"
    )
    _add_workers(d)
    d.add_argument("--cell-size-m", type=float, default=DEFAULT_CELL_SIZE_M, help="radio-map grid cell [m]")
    d.add_argument("--min-count", type=int, default=DEFAULT_MIN_COUNT, help="radio map: min scans per entry")
    d.add_argument(
        "--set",
        dest="param_sets",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="firmware parameter for every replay (stridefixd --set; repeatable)",
    )
    d.add_argument(
        "--cache", default=None, metavar="DIR", help="import cache (default: <folder of results.json>/cache)"
    )
    d.add_argument("--reimport", action="store_true", help="ignore the cached imports")
    _add_quiet(d)
    d.set_defaults(_bench=_run_crowd_map_cli)


def _run_crowd_map_cli(args: argparse.Namespace) -> int:
    from stridefix_analyzer.crowd.solve import parse_anchors
    from stridefix_analyzer.crowd.walks import CrowdInputError

    from stridefix_lab.realbench.crowdmap import CrowdMapConfig, format_tables, run_crowd_map

    try:
        parse_anchors(args.anchors)
        cfg = FusionConfig(
            fmt=args.format,
            dirs=args.dirs,
            out_json=Path(args.out),
            stridefixd=args.stridefixd,
            limit=args.limit,
            jobs=args.jobs,
            scheduler=args.scheduler,
            reimport=args.reimport,
            cell_size_m=args.cell_size_m,
            min_count=args.min_count,
            cache_dir=args.cache,
            report=False,
            quiet=console.quiet(),
            param_sets=args.param_sets,
        )
        doc = run_crowd_map(
            CrowdMapConfig(cfg, anchors=args.anchors, solver=args.solver, max_sigma_m=args.max_sigma_m)
        )
    except (RealbenchError, LogReadError, CrowdInputError, SchedulerError) as exc:
        print(f"stridefix-lab realbench: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    print(format_tables(doc))
    print(f"wrote {args.out} ({doc['run_s']['total']:.1f} s)")
    return 0 if any(g["paired"] for g in doc["groups"]) else 1
