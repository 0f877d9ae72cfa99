"""``stridefix import FORMAT ...``: turn files of a public data set into raw-sensor LCM logs.

One sub-command per registered data set (:mod:`stridefix_analyzer.datasets`: every module with a
``DATASET``), built from its protocol (:class:`~.protocol.Dataset`): the inputs, the output arguments
every format shares, then the set's own options (:meth:`~.protocol.Dataset.add_arguments`) and
``--json``. Every format writes either one log per input into a directory (``--out DIR``:
``DIR/<input-stem>.lcmlog``) or, for a single input, one named file (``-o/--output FILE``):
:func:`add_output_arguments`, :func:`output_paths`.
Exit status (:mod:`stridefix_common.exits`): 0 every input imported, 1 an output could not be
written, 2 bad usage or a missing/unreadable input, 3 an input held no valid sensor record (nothing
written for it); with several inputs the worst of theirs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

from stridefix_common.exits import EXIT_FAILURE, EXIT_OK, EXIT_USAGE, input_error_status, worst

from stridefix_analyzer import console, datasets
from stridefix_analyzer.datasets.lines import MalformedLineWarning
from stridefix_analyzer.datasets.protocol import Dataset, DatasetReadError


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Declare ``stridefix import`` and one sub-command per data set."""
    names = datasets.names()
    p: argparse.ArgumentParser = subparsers.add_parser(
        "import",
        help="import real data sets into raw-sensor LCM logs for stridefixd",
        description="Import files of a public data set into raw-sensor LCM event logs "
        "(IMU, MAG, BARO, WIFI, GNSS, TRUTH) that `stridefixd --input lcmlog:FILE` "
        f"replays. Formats: {', '.join(names)}.",
    )
    sub = p.add_subparsers(dest="format", metavar="FORMAT", required=True)
    for name in names:
        ds = datasets.get(name)
        fp = sub.add_parser(name, help=ds.title, description=ds.description)
        fp.add_argument("inputs", nargs="+", metavar=ds.input_metavar, help=ds.input_help)
        add_output_arguments(fp)
        ds.add_arguments(fp)
        fp.add_argument(
            "--json",
            metavar="FILE",
            help="also write the summaries as JSON to FILE (when one input imported)",
        )
        fp.set_defaults(_dataset=ds)
    return p


def run(args: argparse.Namespace) -> int:
    """Import every input of the chosen data set; the exit status (see the module docstring)."""
    ds: Dataset = args._dataset
    options = ds.options(args)
    return run_imports(
        args,
        f"stridefix import {ds.name}",
        args.inputs,
        lambda item, out: ds.import_walk(item, out, **options),
        ds.format_summary,
        ds.summary_keys,
        ds.input_noun,
    )


def add_output_arguments(p: argparse.ArgumentParser) -> None:
    """``--out DIR`` (one log per input) or ``-o/--output FILE`` (a single input): one is required."""
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument(
        "--out", metavar="DIR", help="output directory (created): DIR/<input-stem>.lcmlog per input"
    )
    g.add_argument("-o", "--output", metavar="FILE", help="output log file (a single input only)")


def output_paths(inputs: Sequence[str], args: argparse.Namespace, prog: str) -> list[Path] | None:
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
    args: argparse.Namespace,
    prog: str,
    inputs: Sequence[str],
    do_import: Callable[[str, Path], dict[str, Any]],
    format_summary: Callable[[Mapping[str, Any]], str],
    json_keys: Sequence[str],
    noun: str,
) -> int:
    """The import loop: one input at a time, malformed-line warnings on stderr, a progress line and a
    JSON summary line per input, ``--json`` with all summaries.

    ``do_import(input, out) -> summary dict``. Returns the worst status of the inputs: 0, 3 for an
    input without a valid record (:class:`~.protocol.NothingValidError`), 2 for a missing/unreadable
    one (:class:`~.protocol.DatasetReadError`), 1 when an output could not be written.
    """
    outs = output_paths(inputs, args, prog)
    if outs is None:
        return EXIT_USAGE

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        held.append(f"{prog}: warning: {message}")

    statuses, summaries = [EXIT_OK], []
    for i, (item, out) in enumerate(zip(inputs, outs), 1):
        t0 = time.perf_counter()
        # an input's malformed-line warnings are printed once it imported: an input that did not is
        # one error line, which names the first malformed line itself
        held: list[str] = []
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("always", MalformedLineWarning)
                warnings.showwarning = show
                s = do_import(item, out)
        except DatasetReadError as exc:
            print(f"{prog}: error: {exc}", file=sys.stderr)
            statuses.append(input_error_status(exc))
            continue
        except OSError as exc:
            print(f"{prog}: error: cannot write {out}: {exc}", file=sys.stderr)
            statuses.append(EXIT_FAILURE)
            continue
        for line in held:
            print(line, file=sys.stderr)
        summaries.append(s)
        console.say(f"[{i}/{len(inputs)}] {format_summary(s)} -> {out} ({time.perf_counter() - t0:.2f} s)")
        print(json.dumps({k: s[k] for k in json_keys}))
    if args.json and summaries:  # none: every input failed, and each said so already
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)  # as --out DIR and -o FILE's are
        Path(args.json).write_text(json.dumps(summaries, indent=2) + "\n", encoding="utf-8")
    where = args.output if args.output else args.out
    console.say(f"{prog}: {len(summaries)}/{len(inputs)} {noun}(s) imported into {where}")
    return worst(statuses)
