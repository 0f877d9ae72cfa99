"""``stridefix sim``: run one software-in-the-loop scenario and write the board's CAN log plus truth.

Exit status (:mod:`stridefix_common.exits`, the contract of every ``stridefix`` command): 0 success,
1 the simulation failed or its output could not be written, 2 bad usage or unreadable input (scenario
file missing, bad TOML, unknown key, value out of range).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from stridefix_common.exits import EXIT_FAILURE, EXIT_OK, EXIT_USAGE

from .pipeline import CANDUMP_SUFFIXES, candump_path, simulate, write_outputs
from .scenario import BUILTIN, ScenarioError, resolve_scenario


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "sim",
        help="simulate a walk: write the board's candump log, truth LCM log and a summary",
        description="Simulate a walk with the wearable board and write board.candump (candump -L; "
        "board.log with --candump-suffix .log), "
        "truth.lcmlog (TRUTH, 10 Hz), sim_summary.json and init_truth.ini into --out.",
    )
    p.add_argument(
        "--scenario",
        metavar="NAME|FILE",
        help=f"a built-in scenario ({', '.join(BUILTIN)}) or a scenario TOML file (default: default)",
    )
    p.add_argument("--seed", type=int, help="random seed (overrides the scenario)")
    p.add_argument("--out", metavar="DIR", default="out/sim", help="output directory (default: out/sim)")
    p.add_argument(
        "--stdout",
        action="store_true",
        help="stream the candump lines to stdout instead of DIR/board.candump",
    )
    p.add_argument(
        "--candump-suffix",
        choices=CANDUMP_SUFFIXES,
        default=CANDUMP_SUFFIXES[0],
        help="name the CAN log DIR/board.log instead of DIR/board.candump (the same candump -L lines): "
        "python-can's can.LogReader reads a candump log by the .log suffix; stridefixd takes either",
    )
    p.add_argument(
        "--duration-s", type=float, metavar="S", help="simulated duration [s] (0: until the walk ends)"
    )
    p.add_argument("--loss-rate", type=float, metavar="R", help="CAN frame loss probability 0..1")
    p.add_argument(
        "--board-time-start-ms", type=int, metavar="MS", help="board time of the first frame [ms], 0..2**32-1"
    )
    p.add_argument(
        "--survey",
        action="store_true",
        help="survey mode: stand at each calibration point of the world, scan in 4 orientations "
        "(scenario [survey] keys), instead of walking the route",
    )
    return p


def run(args) -> int:
    t_start = time.perf_counter()
    try:
        scenario = resolve_scenario(args.scenario)
        scenario = scenario.with_overrides(
            **{
                "seed": args.seed,
                "duration_s": None if args.duration_s is None else float(args.duration_s),
                "can.loss_rate": None if args.loss_rate is None else float(args.loss_rate),
                "can.board_time_start_ms": args.board_time_start_ms,
                "survey.enabled": True if getattr(args, "survey", False) else None,
            }
        )
    except ScenarioError as e:
        print(f"stridefix sim: error: {e}", file=sys.stderr)
        return EXIT_USAGE
    suffix = getattr(args, "candump_suffix", CANDUMP_SUFFIXES[0])
    try:
        result = simulate(scenario)
        out_dir = Path(args.out)
        summary = write_outputs(
            result,
            out_dir,
            candump_stream=sys.stdout if args.stdout else None,
            candump_suffix=suffix,
        )
    except OSError as e:
        print(f"stridefix sim: error: cannot write output: {e}", file=sys.stderr)
        return EXIT_FAILURE
    elapsed = time.perf_counter() - t_start
    where = "stdout" if args.stdout else str(candump_path(out_dir, suffix))
    print(
        f"stridefix sim: seed {summary['seed']}, {summary['duration_s']:.1f} s simulated, "
        f"{summary['steps']} steps, {summary['distance_m']:.1f} m, floors {summary['floors_visited']}, "
        f"{summary['frames_total']} frames written to {where} ({summary['frames_dropped']} dropped), "
        f"{summary['imu_samples']} IMU samples, {summary['wifi_scans']} Wi-Fi scans"
        + (
            f", {summary['n_points']} calibration points x {summary['scans_per_point']} scans"
            if "n_points" in summary
            else ""
        )
        + (f", {summary['n_reference_points']} reference points" if "n_reference_points" in summary else "")
        + "; "
        f"outputs in {out_dir}; {elapsed:.2f} s",
        file=sys.stderr,
    )
    return EXIT_OK
