"""The `stridefix` console script: one sub-command per job a user does on their own walks.

Simulate a walk, import a data set, analyze and report a log, compare two runs, score a competition
submission, build a radio map (from a survey or from crowdsourced walks), watch a walk live, inspect
the channels. The machinery (registry, lazy import, global options, exit-status help) is
:mod:`stridefix_analyzer.cliapp`; this module registers and dispatches and nothing else; nothing
imports from it. Benchmarks and the papers' experiments are the lab's console script,
``stridefix-lab`` (:mod:`stridefix_lab.cli`).
"""

from __future__ import annotations

import sys

from stridefix_analyzer.cliapp import CommandLine, split_global

# sub-command name -> module providing add_parser() and run()
SUBCOMMANDS = {
    "sim": "stridefix_sim.cli",
    "import": "stridefix_analyzer.datasets.cli",
    "analyze": "stridefix_analyzer.scoring.analyze",
    "report": "stridefix_analyzer.scoring.report",
    "compare": "stridefix_analyzer.scoring.compare",
    "score": "stridefix_analyzer.scoring.ipin_cli",
    "radiomap": "stridefix_analyzer.radiomap.cli",
    "site": "stridefix_analyzer.radiomap.site_cli",
    "crowd": "stridefix_analyzer.crowd.cli",
    "live": "stridefix_analyzer.live.server",
    "spy": "stridefix_analyzer.spy",
    "export": "stridefix_analyzer.export.cli",
}

# sub-command name -> "module:function" rewriting argv before parsing
ARGV_REWRITES: dict[str, str] = {}

APP = CommandLine(
    prog="stridefix",
    description="StrideFix tools: simulate a walk, analyze LCM logs, render reports.",
    subcommands=SUBCOMMANDS,
    argv_rewrites=ARGV_REWRITES,
)
build_parser = APP.build_parser
rewrite_argv = APP.rewrite_argv
main = APP.main
__all__ = ["APP", "ARGV_REWRITES", "SUBCOMMANDS", "build_parser", "main", "rewrite_argv", "split_global"]

if __name__ == "__main__":
    sys.exit(main())
