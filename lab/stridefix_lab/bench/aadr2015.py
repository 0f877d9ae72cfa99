"""``stridefix-lab bench aadr2015``: the auto-adaptive dead-reckoning paper's experiment in SIL: the
fusion schemes at the reference points at each pace, against the paper's table (:mod:`.fusion`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from stridefix_analyzer.firmware import Firmware

from stridefix_lab.bench import fusion
from stridefix_lab.bench.registry import Bench


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--paces",
        default="slow,normal,fast",
        metavar="LIST",
        help="comma-separated paces (default: slow,normal,fast)",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    paces = [p for p in args.paces.split(",") if p]
    doc = fusion.run_aadr2015(seeds, paces, firmware, out / "aadr2015", args.sets)
    print(fusion.format_table(doc["table"], paper=True))
    red = doc["adaptive_reduction_pct"]
    print(
        f"adaptive vs Wi-Fi only: mean error {'-' if red is None else f'{red:.1f} %'} lower "
        f"(paper: 43 %); targets met: {doc['targets_met']}"
    )
    print(f"wrote {out / 'aadr2015' / 'aadr2015.json'} ({doc['run_s']:.0f} s)")
    return fusion.missed_targets_aadr2015(doc)


BENCH = Bench(
    "aadr2015",
    "the auto-adaptive DR paper's experiment: fusion schemes at the reference points",
    _run,
    seeds="1,2,3,4,5",
    add_arguments=_add_arguments,
    in_make_bench=True,
)
