"""``stridefix site``: the site of one's own building from one's own walks, and the stridefixd settings
that go with it.

The options of ``radiomap build`` (:mod:`.options`) plus the firmware the walks are replayed with;
:func:`~.learn.make_site_from_walks` does the work. This module only declares and dispatches.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys

from stridefix_common.exits import EXIT_USAGE, input_error_status

from stridefix_analyzer import datasets
from stridefix_analyzer.firmware import Firmware, FirmwareError, add_stridefixd_argument
from stridefix_analyzer.parallel import add_jobs_argument, add_scheduler_argument
from stridefix_analyzer.radiomap.learn import format_learned, make_site_from_walks
from stridefix_analyzer.radiomap.make import INPUT_ERRORS, SiteOptions
from stridefix_analyzer.radiomap.options import add_site_options
from stridefix_analyzer.radiomap.show import format_summary

#: one detection per (RP, AP) is kept: with the matcher's map levels averaged over all of a cell's
#: scans, one detection is weak evidence, not noise (realbench's choice on walk-built maps)
SITE_MIN_COUNT = 1


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare ``stridefix site``."""
    p = subparsers.add_parser(
        "site",
        help="site file + stridefixd settings of your building, from walks with known points or a survey",
        description="Build the site of your own building from your own recordings: walks whose logs "
        "carry TRUTH at known points (an imported msindoor trace: its waypoints) or a survey. Every walk "
        "is replayed through stridefixd to learn what a radio map cannot give (the map rotation, the "
        "heading mode and the Weinberg stride constant); then the site is built as `radiomap build` "
        "builds it (radio map, --floor-plan walls, --building description) and the settings are "
        "written to SITE.ini for `stridefixd --site SITE.sfsite --config SITE.ini`. The walk you "
        "look at afterwards must not be one of LOG.",
    )
    p.add_argument(
        "logs", nargs="+", metavar="LOG", help="raw-sensor LCM logs with TRUTH ('a,b': one walk of two files)"
    )
    p.add_argument("--out", required=True, metavar="SITE.sfsite", help="site file to write")
    p.add_argument(
        "--config-out",
        default=None,
        metavar="SITE.ini",
        help="stridefixd settings to write (default: the site's name with .ini)",
    )
    p.add_argument(
        "--format",
        choices=datasets.names(),
        default=None,
        help="the walks were imported from this data set: replay them with its device settings "
        "(msindoor and gsd: magcal.enable=0, heading.mount_offset_deg=90), also written to SITE.ini",
    )
    p.add_argument(
        "--set",
        dest="param_sets",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a device setting the walks need (stridefixd --set; repeatable), also written to SITE.ini",
    )
    p.add_argument(
        "--no-learn",
        action="store_true",
        help="replay nothing: the map rotation as given, no stride or heading settings learned",
    )
    p.add_argument(
        "--learn-beacons",
        action="store_true",
        help="without --beacon-table, also place BLE beacons from the walks alone (off: a beacon placed "
        "from readings between sparse known points is metres off, and its fixes cost more than they give)",
    )
    p.add_argument(
        "--no-context-map",
        dest="context_map",
        action="store_false",
        help="no one-building context map (written unless --building has [[building]] entries): the "
        "multi-scheme controller then does not run and POSE copies controller.init_scheme's pose",
    )
    add_site_options(p, min_count=SITE_MIN_COUNT)
    add_stridefixd_argument(p)
    add_scheduler_argument(p, "processes")
    add_jobs_argument(p, "processes of --scheduler processes or local", dest="workers")
    return p


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix site``; returns the exit status."""
    prog = "stridefix site"
    sets = [*(datasets.get(args.format).firmware_sets if args.format else ()), *args.param_sets]
    config_out = args.config_out or os.path.splitext(args.out)[0] + ".ini"
    opts = SiteOptions(**{f.name: getattr(args, f.name) for f in dataclasses.fields(SiteOptions)})
    try:
        summary = make_site_from_walks(
            args.logs,
            args.out,
            config_out,
            opts,
            Firmware(args.stridefixd),
            sets,
            learn=not args.no_learn,
            scheduler=args.scheduler,
            workers=args.workers,
        )
    except FirmwareError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except INPUT_ERRORS as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    print(format_summary(summary))
    print(format_learned(summary["learned"]))
    print(f"wrote {args.out} ({summary['bytes']} bytes) and {config_out}")
    print(f"next: stridefixd --replay WALK.lcmlog --site {args.out} --config {config_out} --log RUN.lcmlog")
    return 0
