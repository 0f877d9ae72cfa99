"""``stridefix bench``: benchmarks that run the whole SIL chain and print numbers against targets.

``sil-pdr`` (issue 3): for each scenario and seed, simulate the walk, replay it through the real
``stridefixd`` binary in PDR-only mode, and score the log with the evaluation protocol of DESIGN.md.
It reports step-count error, heading RMS error, final position error as % of the distance walked
and the floor hit rate, next to the targets, and writes ``OUT/sil_pdr.json``.

The start position is truth-initialised (the simulator's ``init_truth.ini``): PDR alone has no
absolute position. Site facts the firmware will later read from the site file (map rotation) are
passed from the simulator's summary with ``--set``.

Stride calibration, as a user would do it: before the scored walks, the same person (same seed)
walks one lap of the floor-0 loop at normal pace; stridefixd runs on it and K = lap distance /
Σ (amax − amin)^¼ over its STEP messages. The scored walk then runs with that K. Nothing of the
scored walk's truth enters the estimator; the person's true K is reported beside the learnt one.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.scoring.analyze import run_analyze

CALIBRATION_SCENARIO = """# one lap of the floor-0 loop at normal pace, no pauses: the stride calibration walk
[walk]
route = "loop"
laps = 1
pace = "normal"
pause = []
"""

DEFAULT_OUT = "out/bench"
DEFAULT_SCENARIOS = ["default", "pace_slow", "pace_normal", "pace_fast"]
REPO = Path(__file__).resolve().parents[2]
DEFAULT_STRIDEFIXD = REPO / "build" / "firmware" / "stridefixd"

# Issue 3's targets on the default scenarios.
TARGETS = {"step_error_pct_abs_max": 1.0, "floor_hit_rate_min": 0.99, "final_error_pct_max": 2.0}


class BenchError(RuntimeError):
    """A stage of the chain failed; the message names the stage and its output."""


def _run(cmd: list[str], what: str) -> subprocess.CompletedProcess:
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise BenchError(f"{what} failed (exit {proc.returncode}): {' '.join(cmd)}\n{proc.stderr[-2000:]}")
    return proc


def _stridefix() -> str:
    return str(Path(sys.executable).with_name("stridefix"))


def calibrate_k(seed: int, stridefixd: Path, out_dir: Path, sets: list[str] = ()) -> float:
    """Weinberg K of the person of ``seed`` from a calibration lap of known length (see module doc)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    scenario = out_dir / "calibration.toml"
    scenario.write_text(CALIBRATION_SCENARIO)
    _run(
        [_stridefix(), "sim", "--out", str(out_dir), "--seed", str(seed), "--scenario", str(scenario)],
        f"calibration sim seed {seed}",
    )
    summary = json.loads((out_dir / "sim_summary.json").read_text())
    log = out_dir / "stridefixd.lcmlog"
    _run(
        [
            str(stridefixd),
            "--input",
            str(out_dir / "board.candump"),
            "--log",
            str(log),
            "-q",
            "--config",
            str(out_dir / "init_truth.ini"),
            *[a for kv in sets for a in ("--set", kv)],
        ],
        f"calibration stridefixd seed {seed}",
    )
    steps = read_logs([str(log)]).tables["STEP"]
    weinberg_sum = float(np.sum(np.asarray(steps["accel_range_mps2"], float) ** 0.25))
    if weinberg_sum <= 0:
        raise BenchError(f"calibration walk seed {seed}: no steps detected in {log}")
    return summary["distance_m"] / weinberg_sum


def run_one(
    scenario: str, seed: int, stridefixd: Path, out_dir: Path, weinberg_k: float | None, sets: list[str] = ()
) -> dict:
    """Simulate one walk, replay it through stridefixd, score it; return the row of numbers."""
    out_dir.mkdir(parents=True, exist_ok=True)
    stridefix = _stridefix()
    t0 = time.perf_counter()
    sim = [stridefix, "sim", "--out", str(out_dir), "--seed", str(seed)]
    if scenario != "default":
        sim += ["--scenario", scenario]
    _run(sim, f"sim {scenario} seed {seed}")
    summary = json.loads((out_dir / "sim_summary.json").read_text())
    log = out_dir / "stridefixd.lcmlog"
    fw = [
        str(stridefixd),
        "--input",
        str(out_dir / "board.candump"),
        "--log",
        str(log),
        "-q",
        "--config",
        str(out_dir / "init_truth.ini"),
    ]
    if "map_rotation_deg" in summary:
        fw += ["--set", f"heading.map_rotation_deg={summary['map_rotation_deg']}"]
    if weinberg_k is not None:
        fw += ["--set", f"stride.weinberg_k={weinberg_k:.6f}"]
    for kv in sets:
        fw += ["--set", kv]
    _run(fw, f"stridefixd {scenario} seed {seed}")
    metrics, _ = run_analyze(
        [str(log), str(out_dir / "truth.lcmlog")],
        str(out_dir),
        label=f"{scenario} seed {seed}, PDR only, truth-initialised start",
    )
    steps = metrics["steps"]
    return {
        "scenario": scenario,
        "seed": seed,
        "weinberg_k_used": weinberg_k,
        "weinberg_k_true": summary.get("weinberg_k"),
        "duration_s": summary.get("duration_s"),
        "distance_m": metrics["distance_walked_m"],
        "steps_truth": steps["truth"],
        "steps_detected": steps["detected"],
        "step_error_pct": steps["error_pct"],
        "heading_rms_deg": metrics["heading_error"]["rms_deg"],
        "mean_error_m": metrics["position_error_m"]["mean"],
        "final_error_m": metrics["final_error_m"],
        "final_error_pct": metrics["final_error_pct_of_distance"],
        "floor_hit_rate": metrics["floor_hit_rate"],
        "floors": metrics["floors_in_truth"],
        "run_s": time.perf_counter() - t0,
    }


def meets_targets(row: dict) -> dict:
    """Which of issue 3's targets one run meets."""

    def ok(value, test):
        return None if value is None or not np.isfinite(value) else bool(test(value))

    return {
        "steps": ok(row["step_error_pct"], lambda v: abs(v) <= TARGETS["step_error_pct_abs_max"]),
        "floor": ok(row["floor_hit_rate"], lambda v: v >= TARGETS["floor_hit_rate_min"]),
        "final": ok(row["final_error_pct"], lambda v: v <= TARGETS["final_error_pct_max"]),
    }


def format_table(rows: list[dict]) -> str:
    head = (
        f"{'scenario':<12}{'seed':>5}{'K used':>7}{'K true':>7}{'dist m':>8}{'steps':>7}{'err %':>7}{'hdg°':>6}"
        f"{'mean m':>8}{'final m':>8}{'final %':>8}{'floor':>7}  targets (steps/floor/final)"
    )
    lines = [head]
    for r in rows:
        t = r["targets"]
        mark = " ".join({True: "ok", False: "MISS", None: "-"}[t[k]] for k in ("steps", "floor", "final"))
        fh = r["floor_hit_rate"]
        ku = r["weinberg_k_used"]
        kt = r["weinberg_k_true"]
        lines.append(
            f"{r['scenario']:<12}{r['seed']:>5}{(ku if ku else float('nan')):>7.3f}"
            f"{(kt if kt else float('nan')):>7.3f}{r['distance_m']:>8.1f}{r['steps_truth']:>7}"
            f"{r['step_error_pct']:>+7.2f}{r['heading_rms_deg']:>6.1f}{r['mean_error_m']:>8.2f}"
            f"{r['final_error_m']:>8.2f}{r['final_error_pct']:>8.2f}"
            f"{(100 * fh if fh is not None else float('nan')):>6.1f}%  {mark}"
        )
    lines.append(
        f"targets: |step error| <= {TARGETS['step_error_pct_abs_max']} %, floor hit rate >= "
        f"{100 * TARGETS['floor_hit_rate_min']:.0f} %, final error <= "
        f"{TARGETS['final_error_pct_max']} % of distance walked"
    )
    return "\n".join(lines)


def run_sil_pdr(
    scenarios: list[str],
    seeds: list[int],
    stridefixd: Path,
    out: Path,
    calibrate: bool = True,
    sets: list[str] = (),
) -> dict:
    rows = []
    k_by_seed = {}
    if calibrate:
        for seed in seeds:
            print(f"bench sil-pdr: calibration walk, seed {seed}", file=sys.stderr, flush=True)
            k_by_seed[seed] = calibrate_k(seed, stridefixd, out / "sil_pdr" / f"calibration-s{seed}", sets)
    n = len(scenarios) * len(seeds)
    for i, (scenario, seed) in enumerate((s, k) for s in scenarios for k in seeds):
        print(f"bench sil-pdr: [{i + 1}/{n}] {scenario} seed {seed}", file=sys.stderr, flush=True)
        row = run_one(
            scenario, seed, stridefixd, out / "sil_pdr" / f"{scenario}-s{seed}", k_by_seed.get(seed), sets
        )
        row["targets"] = meets_targets(row)
        rows.append(row)
    doc = {
        "bench": "sil_pdr",
        "targets": TARGETS,
        "stride_calibration": calibrate,
        "sets": list(sets),
        "runs": rows,
        "all_targets_met": all(v is not False for r in rows for v in r["targets"].values()),
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "sil_pdr.json").write_text(json.dumps(doc, indent=2, default=float) + "\n")
    return doc


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "bench",
        help="SIL benchmarks: simulate, replay through stridefixd, score against targets",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "which",
        choices=["sil-pdr", "aadr2015", "office-wifi"],
        help="sil-pdr: PDR targets at each pace; aadr2015: the auto-adaptive DR paper's "
        "experiment (fusion schemes at the reference points); office-wifi: the fusion "
        "schemes on the default office walk with a surveyed radio map",
    )
    p.add_argument(
        "--paces",
        default="slow,normal,fast",
        metavar="LIST",
        help="aadr2015: comma-separated paces (default: slow,normal,fast)",
    )
    p.add_argument(
        "--scenarios",
        default=",".join(DEFAULT_SCENARIOS),
        metavar="LIST",
        help=f"comma-separated scenario names (default: {','.join(DEFAULT_SCENARIOS)})",
    )
    p.add_argument(
        "--seeds",
        default=None,
        metavar="LIST",
        help="comma-separated seeds (default: 1,2,3; aadr2015: 1,2,3,4,5)",
    )
    p.add_argument(
        "--stridefixd",
        default=str(DEFAULT_STRIDEFIXD),
        metavar="PATH",
        help=f"the firmware binary (default: {DEFAULT_STRIDEFIXD})",
    )
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
        "--no-calibration",
        action="store_true",
        help="skip the per-person stride calibration walk (use the configured default K)",
    )
    return p


def run(args: argparse.Namespace) -> int:
    from stridefix_analyzer.bench import fusion as bench_fusion

    stridefixd = Path(args.stridefixd)
    if not stridefixd.is_file():
        print(f"stridefix bench: error: {stridefixd}: no such binary (run `make build`)", file=sys.stderr)
        return 2
    default_seeds = "1,2,3,4,5" if args.which == "aadr2015" else "1,2,3"
    try:
        seeds = [int(s) for s in (args.seeds or default_seeds).split(",") if s]
    except ValueError:
        print(f"stridefix bench: error: --seeds {args.seeds!r}: expected integers", file=sys.stderr)
        return 2
    out = Path(args.out)
    try:
        if args.which == "sil-pdr":
            scenarios = [s for s in args.scenarios.split(",") if s]
            doc = run_sil_pdr(
                scenarios, seeds, stridefixd, out, calibrate=not args.no_calibration, sets=args.sets
            )
            print(format_table(doc["runs"]))
            print(f"wrote {os.path.join(args.out, 'sil_pdr.json')}")
        elif args.which == "aadr2015":
            paces = [p for p in args.paces.split(",") if p]
            doc = bench_fusion.run_aadr2015(seeds, paces, stridefixd, out / "aadr2015", args.sets)
            print(bench_fusion.format_table(doc["table"], paper=True))
            red = doc["adaptive_reduction_pct"]
            print(
                f"adaptive vs Wi-Fi only: mean error {'-' if red is None else f'{red:.1f} %'} lower "
                f"(paper: 43 %); targets met: {doc['targets_met']}"
            )
            print(f"wrote {out / 'aadr2015' / 'aadr2015.json'} ({doc['run_s']:.0f} s)")
        else:
            doc = bench_fusion.run_office(seeds, stridefixd, out / "office_wifi", args.sets)
            print(bench_fusion.format_table(doc["table"], paper=False))
            print(f"targets (kalman mean <= 2.0 m, p95 <= 4.5 m) met: {doc['targets_met']}")
            print(f"wrote {out / 'office_wifi' / 'office_wifi.json'} ({doc['run_s']:.0f} s)")
    except BenchError as exc:
        print(f"stridefix bench: error: {exc}", file=sys.stderr)
        return 1
    return 0
