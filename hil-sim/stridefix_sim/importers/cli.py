"""``stridefix import FORMAT ...``: turn files of a public data set into raw-sensor LCM logs.

Each format is a module of this package providing ``add_parser(subparsers)`` (its own sub-command and
arguments) and ``run(args) -> int``; adding one is one entry in :data:`FORMATS`. Every format writes
either one log per input into a directory (``--out DIR``: ``DIR/<input-stem>.lcmlog``) or, for a single
input, one named file (``-o/--output FILE``): :func:`add_output_arguments`, :func:`output_paths`.
Exit status: 0 success, 1 the import failed, 2 bad usage or a missing/unreadable input.
"""
from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

# format name -> module providing add_parser() and run()
FORMATS = {
    "msindoor": "stridefix_sim.importers.msindoor",
    "gsd": "stridefix_sim.importers.gsd",
}


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare ``stridefix import`` and one sub-command per format."""
    p = subparsers.add_parser(
        "import", help="import real data sets into raw-sensor LCM logs for stridefixd",
        description="Import files of a public data set into raw-sensor LCM event logs "
                    "(IMU, MAG, BARO, WIFI, GNSS, TRUTH) that `stridefixd --input lcmlog:FILE` "
                    f"replays. Formats: {', '.join(FORMATS)}.")
    sub = p.add_subparsers(dest="format", metavar="FORMAT", required=True)
    for module_name in FORMATS.values():
        module = importlib.import_module(module_name)
        fp = module.add_parser(sub)
        fp.set_defaults(_import_run=module.run)
    return p


def run(args) -> int:
    """Dispatch to the chosen format's ``run``."""
    return int(args._import_run(args) or 0)


def add_output_arguments(p: argparse.ArgumentParser) -> None:
    """``--out DIR`` (one log per input) or ``-o/--output FILE`` (a single input): one is required."""
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--out", metavar="DIR",
                   help="output directory (created): DIR/<input-stem>.lcmlog per input")
    g.add_argument("-o", "--output", metavar="FILE",
                   help="output log file (a single input only)")


def output_paths(inputs: list, args, prog: str) -> list[Path] | None:
    """The output log of each input, or None after printing a usage error (``-o`` with several)."""
    if args.output is not None:
        if len(inputs) != 1:
            print(f"{prog}: error: -o/--output takes a single input ({len(inputs)} given); "
                  "use --out DIR for several", file=sys.stderr)
            return None
        return [Path(args.output)]
    return [Path(args.out) / (Path(i).stem + ".lcmlog") for i in inputs]
