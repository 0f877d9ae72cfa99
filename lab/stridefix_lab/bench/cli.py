"""``stridefix-lab bench``: benchmarks that run the whole chain and print numbers against targets.

One sub-command per bench of :func:`.registry.benches` (``--list`` names them); ``all`` runs every
bench that ``make bench`` runs, on to the end when one misses. Each bench writes its JSON, prints its
table and returns the lines of the targets it missed.

Exit status: 0 every target met; 1 a target missed (one ``TARGET MISSED: ...`` line per miss on
stdout, naming the figure, its value and the target; the JSON is written either way) or a stage of
the chain failed; 2 bad usage (no firmware binary, bad ``--seeds``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware, FirmwareError, add_stridefixd_argument

from stridefix_lab.bench.registry import Bench, BenchUsageError, benches
from stridefix_lab.stages import StageError

DEFAULT_OUT = "out/bench"
ALL = "all"


def exit_status(missed: list[str]) -> int:
    """Prints one ``TARGET MISSED:`` line per miss; 1 when there is any, else 0."""
    for line in missed:
        print(f"TARGET MISSED: {line}")
    return 1 if missed else 0


def _add_common(p: argparse.ArgumentParser, seeds: str) -> None:
    p.add_argument("--seeds", default=None, metavar="LIST", help=f"comma-separated seeds (default: {seeds})")
    add_stridefixd_argument(p)
    p.add_argument(
        "--out", default=DEFAULT_OUT, metavar="DIR", help=f"output directory (default: {DEFAULT_OUT})"
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        dest="sets",
        help="passed to stridefixd (e.g. attitude.mode=1), to compare variants; repeatable",
    )


def _declare(p: argparse.ArgumentParser, bench: Bench) -> argparse.ArgumentParser:
    """``p`` with the common options (``bench``'s seeds as their default) and the bench's own."""
    _add_common(p, bench.seeds)
    if bench.add_arguments is not None:
        bench.add_arguments(p)
    return p


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    found = benches()
    p: argparse.ArgumentParser = subparsers.add_parser(
        "bench",
        help="benchmarks: simulate, replay through stridefixd, score against targets",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--list", action="store_true", help="name every bench with its help, and exit")
    sub = p.add_subparsers(dest="which", metavar="BENCH")
    for bench in found.values():
        _declare(sub.add_parser(bench.name, help=bench.help, description=bench.help), bench)
    every = sub.add_parser(ALL, help="every bench make bench runs, with its default options")
    _add_common(every, "each bench's")
    return p


def _list(found: dict[str, Bench]) -> int:
    for bench in found.values():
        where = " (make bench)" if bench.in_make_bench else ""
        print(f"{bench.name:<14} {bench.help}{where}")
    return 0


def _run_one(bench: Bench, args: argparse.Namespace) -> int:
    firmware = Firmware(args.stridefixd)
    try:
        if bench.needs_firmware:
            firmware.check_executable()
    except FirmwareError as exc:
        print(f"stridefix-lab bench: error: {exc}", file=sys.stderr)
        return 2
    try:
        seeds = [int(s) for s in (args.seeds or bench.seeds).split(",") if s]
    except ValueError:
        print(f"stridefix-lab bench: error: --seeds {args.seeds!r}: expected integers", file=sys.stderr)
        return 2
    try:
        missed = bench.run(args, firmware, seeds, Path(args.out))
    except StageError as exc:
        print(f"stridefix-lab bench {bench.name}: error: {exc}", file=sys.stderr)
        return 1
    except BenchUsageError as exc:
        print(f"stridefix-lab bench {bench.name}: error: {exc}", file=sys.stderr)
        return 2
    return exit_status(missed)


def _run_all(found: dict[str, Bench], args: argparse.Namespace) -> int:
    """Every ``make bench`` bench with its own defaults and the given common options."""
    status = 0
    for bench in (b for b in found.values() if b.in_make_bench):
        parser = _declare(argparse.ArgumentParser(prog=f"stridefix-lab bench {bench.name}"), bench)
        own = parser.parse_args(["--stridefixd", str(args.stridefixd), "--out", args.out])
        own.seeds, own.sets = args.seeds, args.sets
        print(f"== bench {bench.name}", flush=True)
        status = max(status, _run_one(bench, own))
    return status


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix-lab bench``; returns the exit status (module docstring)."""
    found = benches()
    if args.list:
        return _list(found)
    if args.which is None:
        print("stridefix-lab bench: error: name a bench (--list names them) or 'all'", file=sys.stderr)
        return 2
    if args.which == ALL:
        return _run_all(found, args)
    return _run_one(found[args.which], args)
