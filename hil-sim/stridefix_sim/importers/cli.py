"""``stridefix import FORMAT ...``: turn files of a public data set into raw-sensor LCM logs.

Each format is a module of this package providing ``add_parser(subparsers)`` (its own sub-command and
arguments) and ``run(args) -> int``; adding one (e.g. ``gsd``) is one entry in :data:`FORMATS`.
Exit status: 0 success, 1 the import failed, 2 bad usage or a missing/unreadable input.
"""
from __future__ import annotations

import argparse
import importlib

# format name -> module providing add_parser() and run()
FORMATS = {
    "msindoor": "stridefix_sim.importers.msindoor",
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
