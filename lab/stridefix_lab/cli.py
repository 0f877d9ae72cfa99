"""The `stridefix-lab` console script: the benchmarks and the papers' experiments beside the product.

``bench NAME``  the benchmarks, one module of :mod:`stridefix_lab.bench` each (``bench --list``);
``realbench``   leave-one-walk-out on real data sets (fusion, PDR distance, crowd-built maps);
``crowd``       the crowdsourcing thesis's model search (``models``) and its table (``experiment``).
The lab calls the product (:mod:`stridefix_analyzer`, :mod:`stridefix_sim`) through Python functions;
the machinery is the product's :mod:`stridefix_analyzer.cliapp`; nothing imports from this module.
"""

from __future__ import annotations

import sys

from stridefix_analyzer.cliapp import CommandLine

SUBCOMMANDS = {
    "bench": "stridefix_lab.bench.cli",
    "realbench": "stridefix_lab.realbench.cli",
    "crowd": "stridefix_lab.crowd.cli",
}

ARGV_REWRITES = {
    # `realbench --format ...` = `realbench fusion ...`
    "realbench": "stridefix_lab.realbench.cli:with_default_bench",
}

APP = CommandLine(
    prog="stridefix-lab",
    description="StrideFix lab: benchmarks against targets, real-data benches, the papers' experiments.",
    subcommands=SUBCOMMANDS,
    argv_rewrites=ARGV_REWRITES,
)
build_parser = APP.build_parser
rewrite_argv = APP.rewrite_argv
main = APP.main

if __name__ == "__main__":
    sys.exit(main())
