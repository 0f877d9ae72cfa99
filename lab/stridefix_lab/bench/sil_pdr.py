"""``stridefix-lab bench sil-pdr``: the PDR targets on SIL walks.

For each scenario and seed, simulate the walk, replay it through the real
``stridefixd`` binary in PDR-only mode, and score the log with the evaluation protocol of DESIGN.md.
It reports step-count error, heading RMS error, final position error as % of the distance walked
and the floor hit rate, next to the targets, the mean error and the IPIN score
(:func:`~stridefix_analyzer.scoring.metrics.ipin_score`), and writes ``OUT/sil_pdr.json``.

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
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer import console, schemes
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.scoring.analyze import run_analyze

from stridefix_lab.bench.registry import Bench
from stridefix_lab.stages import StageError, replay, simulate

CALIBRATION_SCENARIO = """# one lap of the floor-0 loop at normal pace, no pauses: the stride calibration walk
[walk]
route = "loop"
laps = 1
pace = "normal"
pause = []
"""

DEFAULT_SCENARIOS = ["default", "pace_slow", "pace_normal", "pace_fast"]

#: how every row started: the replay has no site, so pdr_only starts at the config pose, the truth
START = f"{schemes.PDR_ONLY}, truth-initialised (the simulator's init_truth.ini)"

# The targets on the default scenarios.
TARGETS = {"step_error_pct_abs_max": 1.0, "floor_hit_rate_min": 0.99, "final_error_pct_max": 2.0}


class BenchError(StageError):
    """A stage of a benchmark failed; the message names the stage and its output."""


def calibrate_k(seed: int, firmware: Firmware, out_dir: Path, sets: Sequence[str] = ()) -> float:
    """Weinberg K of the person of ``seed`` from a calibration lap of known length (see module doc)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    scenario = out_dir / "calibration.toml"
    scenario.write_text(CALIBRATION_SCENARIO)
    summary = simulate(scenario, seed, out_dir, f"calibration sim seed {seed}", BenchError)
    log = out_dir / "stridefixd.lcmlog"
    replay(
        firmware,
        f"calibration stridefixd seed {seed}",
        BenchError,
        input=out_dir / "board.candump",
        log=log,
        sets=sets,
        extra=["--config", str(out_dir / "init_truth.ini")],
    )
    steps = read_logs([str(log)]).tables["STEP"]
    weinberg_sum = float(np.sum(np.asarray(steps["accel_range_mps2"], float) ** 0.25))
    if weinberg_sum <= 0:
        raise BenchError(f"calibration walk seed {seed}: no steps detected in {log}")
    return summary["distance_m"] / weinberg_sum


def run_one(
    scenario: str,
    seed: int,
    firmware: Firmware,
    out_dir: Path,
    weinberg_k: float | None,
    sets: Sequence[str] = (),
) -> dict[str, Any]:
    """Simulate one walk, replay it through stridefixd, score it; return the row of numbers."""
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    summary = simulate(
        None if scenario == "default" else scenario, seed, out_dir, f"sim {scenario} seed {seed}", BenchError
    )
    log = out_dir / "stridefixd.lcmlog"
    fw_sets = []
    if "map_rotation_deg" in summary:
        fw_sets.append(f"heading.map_rotation_deg={summary['map_rotation_deg']}")
    if weinberg_k is not None:
        fw_sets.append(f"stride.weinberg_k={weinberg_k:.6f}")
    replay(
        firmware,
        f"stridefixd {scenario} seed {seed}",
        BenchError,
        input=out_dir / "board.candump",
        log=log,
        sets=[*fw_sets, *sets],
        extra=["--config", str(out_dir / "init_truth.ini")],
    )
    metrics, _ = run_analyze(
        [str(log), str(out_dir / "truth.lcmlog")],
        str(out_dir),
        label=f"{scenario} seed {seed}, {START}",
    )
    steps = metrics["steps"]
    return {
        "scenario": scenario,
        "seed": seed,
        "start": START,
        "weinberg_k_used": weinberg_k,
        "weinberg_k_true": summary.get("weinberg_k"),
        "duration_s": summary.get("duration_s"),
        "distance_m": metrics["distance_walked_m"],
        "steps_truth": steps["truth"],
        "steps_detected": steps["detected"],
        "step_error_pct": steps["error_pct"],
        "heading_rms_deg": metrics["heading_error"]["rms_deg"],
        "mean_error_m": metrics["position_error_m"]["mean"],
        "ipin_score_m": metrics["ipin_score"],
        "final_error_m": metrics["final_error_m"],
        "final_error_pct": metrics["final_error_pct_of_distance"],
        "floor_hit_rate": metrics["floor_hit_rate"],
        "floors": metrics["floors_in_truth"],
        "run_s": time.perf_counter() - t0,
    }


def meets_targets(row: dict[str, Any]) -> dict[str, bool | None]:
    """Which of the targets one run meets."""

    def ok(value: float | None, test: Callable[[float], bool]) -> bool | None:
        return None if value is None or not np.isfinite(value) else bool(test(value))

    return {
        "steps": ok(row["step_error_pct"], lambda v: abs(v) <= TARGETS["step_error_pct_abs_max"]),
        "floor": ok(row["floor_hit_rate"], lambda v: v >= TARGETS["floor_hit_rate_min"]),
        "final": ok(row["final_error_pct"], lambda v: v <= TARGETS["final_error_pct_max"]),
    }


def _nan(value: float | None) -> float:
    return float("nan") if value is None else value


def format_table(rows: list[dict[str, Any]]) -> str:
    head = (
        f"{'scenario':<12}{'seed':>5}{'K used':>7}{'K true':>7}{'dist m':>8}{'steps':>7}{'err %':>7}{'hdg°':>6}"
        f"{'mean m':>8}{'ipin m':>8}{'final m':>8}{'final %':>8}{'floor':>7}  targets (steps/floor/final)"
    )
    lines = [f"[{START}]", head]
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
            f"{_nan(r['ipin_score_m']):>8.2f}"
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
    firmware: Firmware,
    out: Path,
    calibrate: bool = True,
    sets: Sequence[str] = (),
) -> dict[str, Any]:
    """Every scenario × seed (after each seed's calibration lap); writes ``OUT/sil_pdr.json``."""
    rows = []
    k_by_seed: dict[int, float] = {}
    if calibrate:
        for seed in seeds:
            console.say(f"bench sil-pdr: calibration walk, seed {seed}")
            k_by_seed[seed] = calibrate_k(seed, firmware, out / "sil_pdr" / f"calibration-s{seed}", sets)
    n = len(scenarios) * len(seeds)
    for i, (scenario, seed) in enumerate((s, k) for s in scenarios for k in seeds):
        console.say(f"bench sil-pdr: [{i + 1}/{n}] {scenario} seed {seed}")
        row = run_one(
            scenario, seed, firmware, out / "sil_pdr" / f"{scenario}-s{seed}", k_by_seed.get(seed), sets
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


# target key of meets_targets() -> (figure, row field, unit, target text)
_TARGET_TEXT = {
    "steps": ("step-count error", "step_error_pct", "%", f"|error| <= {TARGETS['step_error_pct_abs_max']} %"),
    "floor": ("floor hit rate", "floor_hit_rate", "", f">= {TARGETS['floor_hit_rate_min']}"),
    "final": (
        "final error of distance walked",
        "final_error_pct",
        "%",
        f"<= {TARGETS['final_error_pct_max']} %",
    ),
}


def missed_targets(doc: dict[str, Any]) -> list[str]:
    """One line per target missed in a ``sil_pdr.json`` document (empty when all are met)."""
    lines = []
    for row in doc["runs"]:
        for key, met in row["targets"].items():
            if met is False:
                figure, field, unit, target = _TARGET_TEXT[key]
                lines.append(
                    f"sil-pdr {row['scenario']} seed {row['seed']}: {figure} = {row[field]:.3g}"
                    f"{' ' + unit if unit else ''} (target {target})"
                )
    return lines


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--scenarios",
        default=",".join(DEFAULT_SCENARIOS),
        metavar="LIST",
        help=f"comma-separated scenario names (default: {','.join(DEFAULT_SCENARIOS)})",
    )
    p.add_argument(
        "--no-calibration",
        action="store_true",
        help="skip the per-person stride calibration walk (use the configured default K)",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    scenarios = [s for s in args.scenarios.split(",") if s]
    doc = run_sil_pdr(scenarios, seeds, firmware, out, calibrate=not args.no_calibration, sets=args.sets)
    print(format_table(doc["runs"]))
    print(f"wrote {out / 'sil_pdr.json'}")
    return missed_targets(doc)


BENCH = Bench(
    "sil-pdr",
    "PDR targets at each pace on the SIL walks (step count, distance, heading)",
    _run,
    seeds="1,2,3",
    add_arguments=_add_arguments,
    in_make_bench=True,
)
