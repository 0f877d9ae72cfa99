"""``stridefix-lab bench office-wifi``: the fusion schemes on the default office walk with a surveyed
radio map, against the office targets (:mod:`.fusion`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from stridefix_analyzer.firmware import Firmware

from stridefix_lab.bench import fusion
from stridefix_lab.bench.registry import Bench


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    doc = fusion.run_office(seeds, firmware, out / "office_wifi", args.sets)
    print(fusion.format_table(doc["table"], paper=False))
    print(f"targets (kalman mean <= 2.0 m, p95 <= 4.5 m) met: {doc['targets_met']}")
    print(f"wrote {out / 'office_wifi' / 'office_wifi.json'} ({doc['run_s']:.0f} s)")
    return fusion.missed_targets_office(doc)


BENCH = Bench(
    "office-wifi",
    "the fusion schemes on the default office walk with a surveyed radio map",
    _run,
    seeds="1,2,3",
    in_make_bench=True,
)
