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
    "msindoor": "stridefix_analyzer.datasets.msindoor",
    "gsd": "stridefix_analyzer.datasets.gsd",
}


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare ``stridefix import`` and one sub-command per format."""
    p = subparsers.add_parser(
        "import",
        help="import real data sets into raw-sensor LCM logs for stridefixd",
        description="Import files of a public data set into raw-sensor LCM event logs "
        "(IMU, MAG, BARO, WIFI, GNSS, TRUTH) that `stridefixd --input lcmlog:FILE` "
        f"replays. Formats: {', '.join(FORMATS)}.",
    )
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
    g.add_argument(
        "--out", metavar="DIR", help="output directory (created): DIR/<input-stem>.lcmlog per input"
    )
    g.add_argument("-o", "--output", metavar="FILE", help="output log file (a single input only)")


def output_paths(inputs: list, args, prog: str) -> list[Path] | None:
    """The output log of each input, or None after printing a usage error (``-o`` with several)."""
    if args.output is not None:
        if len(inputs) != 1:
            print(
                f"{prog}: error: -o/--output takes a single input ({len(inputs)} given); "
                "use --out DIR for several",
                file=sys.stderr,
            )
            return None
        return [Path(args.output)]
    return [Path(args.out) / (Path(i).stem + ".lcmlog") for i in inputs]


def run_imports(
    args, prog: str, inputs: list, do_import, read_error: type, format_summary, json_keys: tuple, noun: str
) -> int:
    """The import loop every format shares: one input at a time, malformed-line warnings on stderr,
    a progress line and a JSON summary line per input, ``--json`` with all summaries.

    ``do_import(input, out) -> summary dict``; ``read_error`` is the format's missing/unreadable-input
    exception. Returns 0, or 2 when an input was missing/unreadable or its output failed.
    """
    import json
    import time
    import warnings

    from stridefix_analyzer.datasets.msindoor import MalformedLineWarning

    outs = output_paths(inputs, args, prog)
    if outs is None:
        return 2

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"{prog}: warning: {message}", file=sys.stderr)

    status, summaries = 0, []
    for i, (item, out) in enumerate(zip(inputs, outs), 1):
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("always", MalformedLineWarning)
                warnings.showwarning = show
                s = do_import(item, out)
        except read_error as exc:
            print(f"{prog}: error: {exc}", file=sys.stderr)
            status = 2
            continue
        except OSError as exc:
            print(f"{prog}: error: cannot write {out}: {exc}", file=sys.stderr)
            status = 2
            continue
        summaries.append(s)
        print(
            f"[{i}/{len(inputs)}] {format_summary(s)} -> {out} ({time.perf_counter() - t0:.2f} s)",
            file=sys.stderr,
        )
        print(json.dumps({k: s[k] for k in json_keys}))
    if args.json:
        Path(args.json).write_text(json.dumps(summaries, indent=2) + "\n", encoding="utf-8")
    where = args.output if args.output else args.out
    print(f"{prog}: {len(summaries)}/{len(inputs)} {noun}(s) imported into {where}", file=sys.stderr)
    return status
