"""``stridefix bench``: benchmarks that run the whole SIL chain and print numbers against targets.

Registers the sub-benches (:data:`BENCHES`: name → runner); the work is in :mod:`.sil_pdr` and
:mod:`.fusion`. Each runner writes its JSON, prints its table and returns the lines of the targets
it missed.

Exit status: 0 every target met; 1 a target missed (one ``TARGET MISSED: ...`` line per miss on
stdout, naming the figure, its value and the target; the JSON is written either way) or a stage of
the chain failed; 2 bad usage (no firmware binary, bad ``--seeds``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from stridefix_analyzer.bench import (
    controller,
    crowd_scale,
    fusion,
    particle_cost,
    perf,
    realdata,
    reliability,
    scale,
    sil_pdr,
    soak,
    sources,
)
from stridefix_analyzer.firmware import Firmware, FirmwareError, add_stridefixd_argument
from stridefix_analyzer.stages import StageError

DEFAULT_OUT = "out/bench"


def _run_sil_pdr(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    scenarios = [s for s in args.scenarios.split(",") if s]
    doc = sil_pdr.run_sil_pdr(
        scenarios, seeds, firmware, out, calibrate=not args.no_calibration, sets=args.sets
    )
    print(sil_pdr.format_table(doc["runs"]))
    print(f"wrote {os.path.join(args.out, 'sil_pdr.json')}")
    return sil_pdr.missed_targets(doc)


def _run_aadr2015(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
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


def _run_office(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    doc = fusion.run_office(seeds, firmware, out / "office_wifi", args.sets)
    print(fusion.format_table(doc["table"], paper=False))
    print(f"targets (kalman mean <= 2.0 m, p95 <= 4.5 m) met: {doc['targets_met']}")
    print(f"wrote {out / 'office_wifi' / 'office_wifi.json'} ({doc['run_s']:.0f} s)")
    return fusion.missed_targets_office(doc)


def _run_sources(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    doc = sources.run_sources(seeds, firmware, out / "sources", args.sets)
    print(sources.format_table(doc))
    print(f"wrote {out / 'sources.json'} ({doc['run_s']:.0f} s)")
    return sources.missed_targets(doc)


def _run_controller(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    doc = controller.run_controller(seeds, firmware, out / "controller", args.sets)
    print(controller.format_table(doc))
    print(f"wrote {out / 'controller.json'} and {len(doc['timelines'])} timelines ({doc['run_s']:.0f} s)")
    return controller.missed_targets(doc)


def _run_real_targets(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del firmware, seeds  # the replays were realbench's
    rows, missed = realdata.check(realdata.load_groups(args.results))
    print(realdata.format_table(rows))
    out.mkdir(parents=True, exist_ok=True)
    (out / "real_targets.json").write_text(
        json.dumps({"results": list(args.results), "targets": rows}, indent=1)
    )
    print(f"wrote {out / 'real_targets.json'}")
    return missed


def _run_reliability(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # one walk (reliability.SEED): every case is the same walk with one fault
    wanted = {f for f in args.faults.split(",") if f}
    known = {c[0] for c in reliability.CASES}
    if wanted - known:
        raise BenchUsageError(
            f"--faults: unknown {sorted(wanted - known)}; known: {', '.join(sorted(known))}"
        )
    cases = [c for c in reliability.CASES if not c[2] or not wanted or c[0] in wanted]
    doc = reliability.run_reliability(firmware, out, cases, site=not args.no_site, sets=args.sets)
    print(reliability.format_table(doc))
    print(f"wrote {out / 'reliability.json'} ({doc['run_s']:.0f} s)")
    return reliability.missed_targets(doc)


def _run_soak(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # one walk (soak.SEED)
    if not 0 < args.checkpoint_h < args.hours:
        raise BenchUsageError(f"--checkpoint-h {args.checkpoint_h}: must be in 0..--hours ({args.hours})")
    doc = soak.run_soak(firmware, out, hours=args.hours, checkpoint_h=args.checkpoint_h, sets=args.sets)
    print(soak.format_table(doc))
    print(f"wrote {out / 'soak.json'}")
    return soak.missed_targets(doc)


def _run_perf(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # fixed walks of the harness and one simulated walk; args.floor: the real-map peer
    doc = perf.run_perf(firmware, out, Path(args.floor))
    print(perf.format_table(doc))
    print(f"wrote {out / 'perf.json'}")
    return perf.missed_targets(doc)


def _run_particle_cost(
    args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path
) -> list[str]:
    del args, seeds  # one fixed walk of the harness
    doc = particle_cost.run_particle_cost(firmware.path, out)
    print(particle_cost.format_table(doc))
    print(f"wrote {out / 'particle_cost.json'}")
    return particle_cost.missed_targets(doc)


def _run_crowd_scale(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del firmware  # no replay: a synthetic fleet of Walk objects
    doc = crowd_scale.run_crowd_scale(
        out,
        n_scans=args.scans,
        n_walks=args.walks,
        scheduler=args.scheduler,
        pair_fraction=args.pair_fraction,
        solve_groups=args.solve_groups,
        seed=seeds[0],
    )
    print(crowd_scale.format_table(doc))
    print(f"wrote {out / 'crowd_scale.json'} ({doc['run_s']:.0f} s)")
    return crowd_scale.missed_targets(doc)


def _run_scale(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # real walks, no seed
    doc = scale.run_scale(firmware.path, out, Path(args.floor))
    print(scale.format_table(doc))
    print(f"wrote {out / 'scale.json'} ({doc['run_s']:.0f} s)")
    return scale.missed_targets(doc)


Runner = Callable[[argparse.Namespace, Firmware, list[int], Path], list[str]]
#: sub-bench name → (runner, default seeds)
BENCHES: dict[str, tuple[Runner, str]] = {
    "sil-pdr": (_run_sil_pdr, "1,2,3"),
    "aadr2015": (_run_aadr2015, "1,2,3,4,5"),
    "office-wifi": (_run_office, "1,2,3"),
    "sources": (_run_sources, "1,2,3"),
    "controller": (_run_controller, "1,2,3,4,5,6,7,8,9,10"),
    "real-targets": (_run_real_targets, "1"),
    "reliability": (_run_reliability, "1"),
    "soak": (_run_soak, "1"),
    "particle-cost": (_run_particle_cost, "1"),
    "perf": (_run_perf, "1"),
    "crowd-scale": (_run_crowd_scale, "1"),
    "scale": (_run_scale, "1"),
}
#: benches that run no firmware (no --stridefixd needed)
NO_FIRMWARE = {"crowd-scale"}


class BenchUsageError(ValueError):
    """A bench option holds a value the bench does not know (exit 2)."""


def exit_status(missed: list[str]) -> int:
    """Prints one ``TARGET MISSED:`` line per miss; 1 when there is any, else 0."""
    for line in missed:
        print(f"TARGET MISSED: {line}")
    return 1 if missed else 0


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    p: argparse.ArgumentParser = subparsers.add_parser(
        "bench",
        help="SIL benchmarks: simulate, replay through stridefixd, score against targets",
        description=f"{__doc__}\nsil-pdr: {sil_pdr.__doc__}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "which",
        choices=list(BENCHES),
        help="sil-pdr: PDR targets at each pace; aadr2015: the auto-adaptive DR paper's "
        "experiment (fusion schemes at the reference points); office-wifi: the fusion "
        "schemes on the default office walk with a surveyed radio map; sources: every scheme on the campus walk "
        "(indoor, door landmark, outdoor GNSS, door landmark, indoor): errors in and out, GNSS accuracy, "
        "landmarks, wall crossings; controller: the multi-scheme controller against every fixed scheme on the "
        "campus2 walks (error per true context, floor hit, transition latency, false switches, radios on); "
        "real-targets: issue 11's "
        "targets on realbench results.json files (--results); reliability: the default walk with each bus "
        "and board fault vs clean (make reliability); soak: an 8-hour walk with faults, RSS and event "
        "accounting (make soak); particle-cost: the particle scheme's instructions per step under callgrind "
        "(1 000 particles, 5 000 walls; target <= 1 million); perf: the core's instructions per IMU, MAG, BARO "
        "sample and per Wi-Fi fix against map size under callgrind, state sizes, no heap, replay speed and peak "
        "RSS against issue 16's budgets; crowd-scale: the crowd fit and graph solve on a "
        "synthetic fleet (100 000 scans / 500 walks) serially and on Dask 1 and 2 workers (target fit + solve "
        "<= 300 s); scale: realbench and radiomap build on one msindoor floor (--floor) serially, on 2 "
        "processes and on Dask 1 and 2 workers, wall times and identical results (~25 min, not in make bench)",
    )
    p.add_argument(
        "--paces",
        default="slow,normal,fast",
        metavar="LIST",
        help="aadr2015: comma-separated paces (default: slow,normal,fast)",
    )
    p.add_argument(
        "--scenarios",
        default=",".join(sil_pdr.DEFAULT_SCENARIOS),
        metavar="LIST",
        help=f"comma-separated scenario names (default: {','.join(sil_pdr.DEFAULT_SCENARIOS)})",
    )
    p.add_argument(
        "--seeds",
        default=None,
        metavar="LIST",
        help="comma-separated seeds (default: 1,2,3; aadr2015: 1,2,3,4,5; controller: 1..10)",
    )
    p.add_argument(
        "--results",
        nargs="*",
        default=[],
        metavar="results.json",
        help="real-targets: the realbench results files to check (run with --true-start)",
    )
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
    p.add_argument(
        "--faults",
        default="",
        metavar="LIST",
        help="reliability: comma-separated fault kinds to run beside the clean run (default: all)",
    )
    p.add_argument(
        "--no-site",
        action="store_true",
        help="reliability: replay without the office site (PDR only; faster, no fused scheme)",
    )
    p.add_argument(
        "--hours", type=float, default=8.0, metavar="H", help="soak: length of the walk [h] (default: 8)"
    )
    p.add_argument(
        "--checkpoint-h",
        type=float,
        default=1.0,
        metavar="H",
        help="soak: read the first peak RSS after this much input [h] (default: 1)",
    )
    p.add_argument(
        "--scans",
        type=int,
        default=crowd_scale.DEFAULT_SCANS,
        help="crowd-scale: scans of the fleet (default 100000)",
    )
    p.add_argument(
        "--walks",
        type=int,
        default=crowd_scale.DEFAULT_WALKS,
        help="crowd-scale: walks of the fleet (default 500)",
    )
    p.add_argument(
        "--scheduler",
        default="local",
        metavar="local|tcp://HOST:PORT",
        help="crowd-scale: Dask runs on LocalClusters of 1 and 2 workers, or on this scheduler (default local)",
    )
    p.add_argument(
        "--pair-fraction",
        type=float,
        default=1.0,
        help="crowd-scale: fit on an unbiased random subsample of this fraction of the pairs (default 1)",
    )
    p.add_argument(
        "--solve-groups",
        default="chunk:1",
        metavar="floor|all|chunk:K",
        help="crowd-scale: walks per solve task (default chunk:1, one walk per task)",
    )
    p.add_argument(
        "--floor",
        default=str(scale.DEFAULT_FLOOR),
        metavar="DIR",
        help=f"scale, perf (its scikit-learn peer on a real map): the msindoor floor folder (default {scale.DEFAULT_FLOOR})",
    )
    p.add_argument(
        "--no-calibration",
        action="store_true",
        help="skip the per-person stride calibration walk (use the configured default K)",
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix bench``; returns the exit status (module docstring)."""
    firmware = Firmware(args.stridefixd)
    try:
        if args.which not in NO_FIRMWARE:
            firmware.check_executable()
    except FirmwareError as exc:
        print(f"stridefix bench: error: {exc}", file=sys.stderr)
        return 2
    runner, default_seeds = BENCHES[args.which]
    try:
        seeds = [int(s) for s in (args.seeds or default_seeds).split(",") if s]
    except ValueError:
        print(f"stridefix bench: error: --seeds {args.seeds!r}: expected integers", file=sys.stderr)
        return 2
    try:
        missed = runner(args, firmware, seeds, Path(args.out))
    except StageError as exc:
        print(f"stridefix bench: error: {exc}", file=sys.stderr)
        return 1
    except BenchUsageError as exc:
        print(f"stridefix bench: error: {exc}", file=sys.stderr)
        return 2
    return exit_status(missed)
