"""``stridefix-lab bench reliability`` (``make reliability``): the default SIL walk with each bus and board
fault, replayed through the real ``stridefixd``, next to the same walk clean.

Each case of :data:`CASES` is one row: a fault kind, its rate (or time), and the scenario keys that
inject it (the simulator's ``[faults]`` table and ``can`` keys; ``stridefix_sim/faults.py``). Every
case walks the same walk (same seed) through the same site (the office survey, built once as
``bench office-wifi`` does) with the truth-initialised start (``init_truth.ini``), so a row differs
from the clean row only by its fault. Per case the table shows:

* frames lost: frames the board sent that the daemon did not use (board frames − HEALTH
  ``frames_ok``, negative when it used duplicates) vs frames affected: the frames the simulator
  damaged (its ground truth, ``sim_summary.json`` ``faults.frames_affected``);
* steps detected vs the clean run; mean position error of ``pdr_only`` and of the primary scheme
  (the one with most POSE messages) clean vs faulty;
* the HEALTH counters that moved: every integer field of the last HEALTH (read generically, so
  counters added to ``health_t`` appear by themselves) that is 0 in the clean run and not here
  (every field that differs is in the JSON);
* recovered (:func:`recovered`): steps within 2 % of clean when fewer than 2 % of the frames were
  lost, both mean errors within 1.5 × clean + 1 m, and PDR producing steps in the last 30 s; a
  stuck BOARD_TIME and a failed IMU have checks of their own (reliability_cases.py: output times and
  error after the stuck clock like the clean run's; with a failed IMU logging to the end, POSE volume,
  no steps, Wi-Fi fixes going on), measured on the case's outputs next to the clean run's and
  described under the table.

Writes ``OUT/reliability.json``; a case that is not recovered is a missed target (``TARGET MISSED``,
exit 1), as with the other benches.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer import console, schemes
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.scoring.analyze import run_analyze

from stridefix_lab.bench import reliability_cases
from stridefix_lab.bench.fusion import build_site
from stridefix_lab.bench.registry import Bench, BenchUsageError
from stridefix_lab.bench.sil_pdr import BenchError
from stridefix_lab.stages import replay, simulate

#: (name, rate shown in the table, scenario overrides {table: {key: value}})
CASES: list[tuple[str, str, dict[str, dict[str, Any]]]] = [
    ("clean", "-", {}),
    ("loss", "1 %", {"can": {"loss_rate": 0.01}}),
    ("loss", "5 %", {"can": {"loss_rate": 0.05}}),
    ("burst", "0.05 % x 20", {"faults": {"burst_rate": 0.0005, "burst_frames": 20}}),
    ("silence", "2 s at 100 s", {"faults": {"silence_at_s": [100.0], "silence_s": 2.0}}),
    ("silence", "10 s at 100 s", {"faults": {"silence_at_s": [100.0], "silence_s": 10.0}}),
    ("duplicate", "1 %", {"faults": {"duplicate_rate": 0.01}}),
    ("reorder", "1 % by 1", {"faults": {"reorder_rate": 0.01, "reorder_frames": 1}}),
    ("reorder", "0.1 % by 5", {"faults": {"reorder_rate": 0.001, "reorder_frames": 5}}),
    ("corrupt", "0.1 %", {"faults": {"corrupt_rate": 0.001}}),
    ("corrupt", "1 %", {"faults": {"corrupt_rate": 0.01}}),
    ("reset", "at 150 s", {"faults": {"reset_at_s": [150.0]}}),
    ("wrap", "at 100 s", {"can": {"board_time_start_ms": 2**32 - 100_000}}),
    # one flipped sign bit of accel_z (9 -> -147 m/s2); at 200 s it costs ~80 steps (at 100 s, none)
    ("implausible", "1 bit at 200 s", {"faults": {"implausible_at_s": [200.0]}}),
    (
        "implausible",
        "0.1 % full scale",
        {"faults": {"implausible_rate": 0.001, "implausible_mode": "full_scale"}},
    ),
    # BOARD_TIME repeats its 100 s value for 60 s while the samples go on
    (
        "board_time_stuck",
        "60 s at 100 s",
        {"faults": {"board_time_stuck_at_s": [100.0], "board_time_stuck_s": 60.0}},
    ),
    # every IMU signal at full scale from 150 s to the end of the walk
    (
        "imu_failed",
        "full scale from 150 s",
        {"faults": {"imu_failed_at_s": [150.0], "imu_failed_s": 3600.0}},
    ),
]
SEED = 1
SCENARIO = "default"
SURVEY = "office_survey"
TAIL_S = 30.0  # PDR must produce steps in the last TAIL_S of the walk
STEPS_TOL = 0.02  # steps within this fraction of clean ...
LOST_MAX = 0.02  # ... when fewer than this fraction of the frames were lost
ERR_FACTOR, ERR_MARGIN_M = 1.5, 1.0  # mean error within ERR_FACTOR x clean + ERR_MARGIN_M
NOT_COUNTERS = ("t_us", "host_t_us")  # integer HEALTH fields that are times, not counters


def case_label(name: str, rate: str) -> str:
    return name if rate == "-" else f"{name} {rate}"


def case_dir(name: str, rate: str) -> str:
    """A directory name for one case: its label with every character not a letter or digit as '_'."""
    return "".join(c if c.isalnum() else "_" for c in case_label(name, rate)).strip("_")


def scenario_toml(overrides: dict[str, dict[str, Any]], duration_s: float | None) -> str:
    """The scenario file of one case (numbers, lists of numbers and strings are all it needs)."""

    def value(v: Any) -> str:
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return json.dumps(v)

    lines = [f"duration_s = {float(duration_s)}"] if duration_s else []
    for table, keys in overrides.items():
        lines.append(f"[{table}]")
        lines += [f"{k} = {value(v)}" for k, v in keys.items()]
    return "\n".join(lines) + "\n"


def health_counters(health: dict[str, Any]) -> dict[str, int]:
    """The integer fields of one HEALTH report, but its times."""
    return {
        k: int(v)
        for k, v in health.items()
        if k not in NOT_COUNTERS and isinstance(v, (int, np.integer)) and not isinstance(v, bool)
    }


def run_case(
    name: str,
    rate: str,
    overrides: dict[str, dict[str, Any]],
    firmware: Firmware,
    out: Path,
    site: Path | None,
    duration_s: float | None,
    sets: Sequence[str] = (),
) -> dict[str, Any]:
    """Simulate one case, replay it through stridefixd and score it; the row of numbers."""
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    scenario = out / "scenario.toml"
    scenario.write_text(scenario_toml(overrides, duration_s))
    summary = simulate(scenario, SEED, out, f"sim {case_label(name, rate)}", BenchError)
    log = out / "stridefixd.lcmlog"
    replay(
        firmware,
        f"stridefixd {case_label(name, rate)}",
        BenchError,
        input=out / "board.candump",
        log=log,
        site=site,
        sets=[f"heading.map_rotation_deg={summary['map_rotation_deg']}", *sets],
        extra=["--config", str(out / "init_truth.ini")],
    )
    metrics, _ = run_analyze([str(log), str(out / "truth.lcmlog")], str(out), label=case_label(name, rate))
    data = read_logs([str(log)], decode=("STEP", "HEALTH"))
    step = data.table("STEP")
    step_t_us = np.asarray(step["t_us"], dtype=np.int64) if step is not None else np.zeros(0, np.int64)
    end_us = summary["board_time_start_ms"] * 1000 + round(summary["duration_s"] * 1e6)
    faults = summary.get("faults", {})
    sent = faults.get("frames_sent_by_board", summary["frames_total"] + summary["frames_dropped"])
    health = health_counters(data.health)
    per_scheme = metrics["per_scheme"]
    return {
        "fault": name,
        "rate": rate,
        "overrides": overrides,
        "dir": str(out),
        "start_us": summary["board_time_start_ms"] * 1000,
        "end_us": end_us,
        "frames_sent": sent,
        "frames_received": summary["frames_total"],
        "frames_ok": health.get("frames_ok"),
        "frames_lost": None if "frames_ok" not in health else sent - health["frames_ok"],
        "frames_affected": faults.get("frames_affected", summary["frames_dropped"]),
        "sim_faults": faults,
        "steps": metrics["steps"]["detected"],
        "steps_truth": metrics["steps"]["truth"],
        "steps_last_30s": int(np.sum(step_t_us > end_us - round(TAIL_S * 1e6))),
        "primary_scheme": metrics["primary_scheme"],
        "mean_error_m": {k: v["position_error_m"]["mean"] for k, v in per_scheme.items()},
        "health": health,
        "run_s": time.perf_counter() - t0,
    }


def recovered(row: dict[str, Any], clean: dict[str, Any]) -> dict[str, bool | None]:
    """The checks of one case against the clean run (None: not applicable) and ``recovered``."""
    lost = row["frames_lost"]
    lost_frac = None if lost is None else lost / max(row["frames_sent"], 1)
    steps_ok = (
        None
        if lost_frac is not None and lost_frac >= LOST_MAX
        else abs(row["steps"] - clean["steps"]) <= STEPS_TOL * clean["steps"]
    )
    err_ok = {}
    for scheme in (schemes.PDR_ONLY, clean["primary_scheme"]):
        e, c = row["mean_error_m"].get(scheme), clean["mean_error_m"].get(scheme)
        err_ok[scheme] = e is not None and c is not None and e <= ERR_FACTOR * c + ERR_MARGIN_M
    checks: dict[str, bool | None] = {
        "steps": steps_ok,
        "error": all(err_ok.values()),
        "steps_in_tail": row["steps_last_30s"] > 0,
    }
    if reliability_cases.KINDS.get(row.get("fault", "")):
        checks = dict.fromkeys(checks)  # replaced by the fault's own
    checks.update(reliability_cases.checks(row, ERR_FACTOR, ERR_MARGIN_M))
    checks["recovered"] = all(v is not False for v in checks.values())
    return checks


def moved_counters(row: dict[str, Any], clean: dict[str, Any]) -> tuple[dict[str, int], dict[str, int]]:
    """(counters 0 in the clean run and not here, every counter that differs): value − clean."""
    h, c = row["health"], clean["health"]
    diff = {k: v - c.get(k, 0) for k, v in h.items() if v != c.get(k, 0)}
    return {k: d for k, d in diff.items() if c.get(k, 0) == 0}, diff


def run_reliability(
    firmware: Firmware,
    out: Path,
    cases: Sequence[tuple[str, str, dict[str, dict[str, Any]]]] = CASES,
    site: bool = True,
    duration_s: float | None = None,
    sets: Sequence[str] = (),
) -> dict[str, Any]:
    """Every case (the first must be the clean run); writes ``OUT/reliability.json``. ``site``:
    replay with the office survey's site (else PDR only); ``duration_s``: shorten the walk."""
    t0 = time.perf_counter()
    if not cases or cases[0][2]:
        raise BenchError("bench reliability: the first case must be the clean run (no overrides)")
    site_path = None
    if site:
        console.say(f"bench reliability: survey ({SURVEY}) and radio map")
        site_path = build_site(SURVEY, firmware, out / "reliability" / "survey")
    rows: list[dict[str, Any]] = []
    for i, (name, rate, overrides) in enumerate(cases):
        console.say(f"bench reliability: [{i + 1}/{len(cases)}] {case_label(name, rate)}")
        where = out / "reliability" / case_dir(name, rate)
        rows.append(run_case(name, rate, overrides, firmware, where, site_path, duration_s, sets))
    clean = rows[0]
    for row in rows:
        row["measures"] = reliability_cases.measure(row, clean)
        row["checks"] = recovered(row, clean)
        row["counters_moved"], row["health_diff"] = moved_counters(row, clean)
    doc = {
        "bench": "reliability",
        "scenario": SCENARIO,
        "seed": SEED,
        "site": None if site_path is None else str(site_path),
        "duration_s": duration_s,
        "sets": list(sets),
        "criteria": {
            "steps_within_pct_of_clean": 100 * STEPS_TOL,
            "steps_checked_below_frames_lost_pct": 100 * LOST_MAX,
            "mean_error_within": f"{ERR_FACTOR} x clean + {ERR_MARGIN_M} m (pdr_only and the primary scheme)",
            "steps_in_last_s": TAIL_S,
        },
        "cases": rows,
        "all_recovered": all(r["checks"]["recovered"] for r in rows),
        "run_s": time.perf_counter() - t0,
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "reliability.json").write_text(json.dumps(doc, indent=2, default=float) + "\n")
    return doc


def _err(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f}"


def format_table(doc: dict[str, Any]) -> str:
    rows = doc["cases"]
    clean = rows[0]
    primary = clean["primary_scheme"]
    w = max(len(case_label(r["fault"], r["rate"])) for r in rows) + 1
    head = (
        f"{'fault':<{w}}{'lost':>7}{'affected':>9}{'steps':>7}{'vs clean':>9}{'tail':>5}"
        f"{'pdr m':>7}{'clean':>7}{primary[:7] + ' m':>10}{'clean':>7}  {'recovered':<10} counters moved"
    )
    lines = [head]
    for r in rows:
        e, ce = r["mean_error_m"], clean["mean_error_m"]
        moved = ", ".join(f"{k} {v:+d}" for k, v in r["counters_moved"].items()) or "-"
        lost = "-" if r["frames_lost"] is None else str(r["frames_lost"])
        lines.append(
            f"{case_label(r['fault'], r['rate']):<{w}}{lost:>7}{r['frames_affected']:>9}{r['steps']:>7}"
            f"{r['steps'] - clean['steps']:>+9}{r['steps_last_30s']:>5}"
            f"{_err(e.get(schemes.PDR_ONLY)):>7}{_err(ce.get(schemes.PDR_ONLY)):>7}"
            f"{_err(e.get(primary)):>10}{_err(ce.get(primary)):>7}  "
            f"{'yes' if r['checks']['recovered'] else 'NO':<10} {moved}"
        )
    lines.append(
        f"(lost = board frames the daemon did not use, negative when it used duplicates; affected = frames the simulator damaged; tail = "
        f"steps in the last {TAIL_S:g} s; errors = mean 2-D error [m]; recovered = steps within "
        f"{100 * STEPS_TOL:g} % of clean when < {100 * LOST_MAX:g} % lost, both errors within "
        f"{ERR_FACTOR:g} x clean + {ERR_MARGIN_M:g} m, steps in the tail; counters moved = HEALTH "
        f"counters 0 in the clean run)"
    )
    for r in rows:
        line = reliability_cases.describe(r)
        if line is not None:
            lines.append(f"{case_label(r['fault'], r['rate'])}: {line}")
    return "\n".join(lines)


def missed_targets(doc: dict[str, Any]) -> list[str]:
    """One line per case that did not recover, naming the checks it failed."""
    lines = []
    for r in doc["cases"]:
        if not r["checks"]["recovered"]:
            failed = [k for k, v in r["checks"].items() if v is False and k != "recovered"]
            lines.append(
                f"reliability {case_label(r['fault'], r['rate'])}: not recovered ({', '.join(failed)})"
            )
    return lines


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--faults",
        default="",
        metavar="LIST",
        help="comma-separated fault kinds to run beside the clean run (default: all)",
    )
    p.add_argument(
        "--no-site",
        action="store_true",
        help="replay without the office site (PDR only; faster, no fused scheme)",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # one walk (SEED): every case is the same walk with one fault
    wanted = {f for f in args.faults.split(",") if f}
    known = {c[0] for c in CASES}
    if wanted - known:
        raise BenchUsageError(
            f"--faults: unknown {sorted(wanted - known)}; known: {', '.join(sorted(known))}"
        )
    cases = [c for c in CASES if not c[2] or not wanted or c[0] in wanted]
    doc = run_reliability(firmware, out, cases, site=not args.no_site, sets=args.sets)
    print(format_table(doc))
    print(f"wrote {out / 'reliability.json'} ({doc['run_s']:.0f} s)")
    return missed_targets(doc)


BENCH = Bench(
    "reliability",
    "the default walk with each bus and board fault vs clean (make reliability)",
    _run,
    add_arguments=_add_arguments,
)
