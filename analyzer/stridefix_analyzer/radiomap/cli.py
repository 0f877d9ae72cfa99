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
from stridefix_analyzer.radiomap.assemble import DEFAULT_MIN_COUNT, site_summary
from stridefix_analyzer.radiomap.contexts import context_map_summary
from stridefix_analyzer.radiomap.make import INPUT_ERRORS, SiteOptions, make_site
from stridefix_analyzer.radiomap.options import add_site_options
from stridefix_analyzer.radiomap.show import format_summary, plot_site


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
    add_site_options(b, min_count=DEFAULT_MIN_COUNT)
    b.set_defaults(learn_beacons=True, context_map=False)
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
