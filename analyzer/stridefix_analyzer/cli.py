"""The `stridefix` console script: one sub-command per job.

Each sub-command lives in the module that does the work and contributes two functions:
``add_parser(subparsers)`` (declares its arguments and help) and ``run(args) -> int`` (the exit status).
Exit status: 0 success, 1 the work failed, 2 bad usage or unreadable input.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# sub-command name -> module providing add_parser() and run()
SUBCOMMANDS = {
    "sim": "stridefix_sim.cli",
    "analyze": "stridefix_analyzer.scoring.analyze",
    "report": "stridefix_analyzer.scoring.report",
    "bench": "stridefix_analyzer.bench.sil_pdr",
    "import": "stridefix_analyzer.datasets.cli",
    "realbench": "stridefix_analyzer.realbench.pdr_distance",
    "radiomap": "stridefix_analyzer.radiomap.cli",
    "crowd": "stridefix_analyzer.crowd.cli",
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="stridefix",
        description="StrideFix tools: simulate a walk, analyze LCM logs, render reports.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, module_name in SUBCOMMANDS.items():
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            # One broken sub-command must not take the others down: it reports itself when used.
            p = sub.add_parser(name, help=f"(unavailable: {exc})")
            p.set_defaults(_run=_unavailable(name, exc))
            continue
        p = module.add_parser(sub)
        p.set_defaults(_run=module.run)
    return parser


def _unavailable(name: str, exc: ImportError):
    def run(_args) -> int:
        print(f"stridefix {name}: unavailable: {exc}", file=sys.stderr)
        return 1

    return run


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        from stridefix_analyzer.realbench.pdr_distance import (
            with_default_bench,  # `realbench --format ...` = `realbench fusion ...`
        )
    except ImportError:
        pass
    else:
        argv = with_default_bench(argv)
    args = build_parser().parse_args(argv)
    return int(args._run(args) or 0)


if __name__ == "__main__":
    sys.exit(main())
