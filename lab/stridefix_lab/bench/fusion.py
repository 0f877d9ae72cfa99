"""``stridefix-lab bench aadr2015`` and ``stridefix-lab bench office-wifi``: the fusion schemes on SIL walks.

aadr2015 replicates the evaluation of Jäger, Süß, Becker ("Multi-Scheme Smartphone Localization with
Auto-Adaptive Dead Reckoning"): the simulator's foyer with 8 APs is surveyed (67 calibration points,
4 orientations × 3 scans), the survey is replayed through stridefixd and turned into a site file by
``stridefix radiomap build``; then the 70 m track is walked at three paces over several seeds, each
walk replayed through stridefixd with that site, and every scheme is scored at the 14 reference points
(TRUTH of source WAYPOINT). Errors of all walks are pooled per scheme; the table sets mean and 75th
percentile next to the paper's (Wi-Fi only 2.94 / 3.54 m, adaptive 1.67 / 2.29 m).

office-wifi does the same on the default two-floor office: survey both floors (``office_survey``),
build the site, walk the default tour, and score every scheme on the 10 Hz truth (targets: kalman
mean ≤ 2.0 m, p95 ≤ 4.5 m).

Every scheme starts at its first fix (no truth initialisation), pdr_only too: its row says so
(``bench sil-pdr`` is the truth-initialised PDR run). Beside mean, p75, p95 and max, the table has
the IPIN score (:func:`~stridefix_analyzer.scoring.metrics.ipin_score`) of the pooled samples. The
survey, the map and the scored walks use different seeds: the map is never built from the walk it
scores.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer import console, schemes
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.radiomap.make import INPUT_ERRORS, SiteOptions, make_site
from stridefix_analyzer.scoring.analyze import run_analyze
from stridefix_analyzer.scoring.metrics import ipin_score, scored_errors

from stridefix_lab.bench.sil_pdr import BenchError
from stridefix_lab.stages import replay, simulate

PAPER = {"wifi_only": (2.94, 3.54), "adaptive": (1.67, 2.29)}
SURVEY_SEED = 1000  # the survey is its own recording, never one of the scored walks
#: how the table labels the PDR baseline: with a site it starts at its first fix like every scheme
PDR_ROW_LABEL = f"{schemes.PDR_ONLY} (from its first fix)"

#: one walk's scored samples per scheme: (2-D error [m], |floor error|), finite errors only
WalkErrors = dict[str, tuple[np.ndarray, np.ndarray]]


def scheme_order(names: Sequence[str]) -> list[str]:
    """Table order of ``names``: the registry's schemes in id order with the PDR-only baseline last,
    then any name the registry does not know (read at call time, so a new scheme needs no edit here)."""
    order = [n for n in schemes.NAMES if n != schemes.PDR_ONLY] + [schemes.PDR_ONLY]
    return [n for n in order if n in names] + sorted(set(names) - set(order))


def simulate_and_log(
    scenario: str, seed: int, firmware: Firmware, out: Path, site: Path | None, sets: Sequence[str] = ()
) -> dict[str, Any]:
    """sim → candump → stridefixd (with the site, if any) → out/stridefixd.lcmlog; returns the summary."""
    out.mkdir(parents=True, exist_ok=True)
    summary = simulate(scenario, seed, out, f"sim {scenario} seed {seed}", BenchError)
    # a survey replay (no site): only the WIFI scans matter; the start pose is irrelevant
    survey_sets = (
        [] if site is not None else [f"heading.map_rotation_deg={summary.get('map_rotation_deg', 0.0)}"]
    )
    replay(
        firmware,
        f"stridefixd {scenario} seed {seed}",
        BenchError,
        input=out / "board.candump",
        log=out / "stridefixd.lcmlog",
        site=site,
        sets=[*survey_sets, *sets],
    )
    return summary


def build_site(survey_scenario: str, firmware: Firmware, out: Path, building: Path | None = None) -> Path:
    """Survey → firmware log → radio map → site file, with ``building`` (building.toml) merged in."""
    summary = simulate_and_log(survey_scenario, SURVEY_SEED, firmware, out, None)
    site = out / "site.sfsite"
    opts = SiteOptions(
        mode="survey",
        name=survey_scenario,
        map_rotation_deg=float(summary.get("map_rotation_deg", 0.0)),
        building=str(building) if building is not None else None,
    )
    if "floor_height_m" in summary:
        opts.floor_height_m = float(summary["floor_height_m"])
    try:
        make_site([str(out / "stridefixd.lcmlog"), str(out / "truth.lcmlog")], site, opts)
    except INPUT_ERRORS as exc:
        raise BenchError(f"radiomap build {survey_scenario} failed: {exc}") from exc
    return site


def score(out: Path, truth_source: str | None, label: str) -> WalkErrors:
    """Per scheme of one walk: its scored samples (see :data:`WalkErrors`)."""
    _, metrics = run_analyze(
        [str(out / "stridefixd.lcmlog"), str(out / "truth.lcmlog")],
        str(out),
        label=label,
        truth_source=truth_source,
    )
    errors: WalkErrors = {}
    for s in metrics.schemes.values():
        e, f = scored_errors(s.match)
        ok = np.isfinite(e)
        errors[s.name] = (e[ok], f[ok])
    return errors


def pooled_table(pooled: dict[str, list[tuple[np.ndarray, np.ndarray]]]) -> dict[str, dict[str, Any]]:
    """Per scheme over the pooled walks: n, mean, p75, p95, max [m] and the IPIN score [m]."""
    table = {}
    for name in scheme_order(list(pooled)):
        e = np.concatenate([w[0] for w in pooled[name]])
        f = np.concatenate([w[1] for w in pooled[name]])
        table[name] = {
            "n": int(e.size),
            "mean_m": float(np.mean(e)),
            "p75_m": float(np.percentile(e, 75)),
            "p95_m": float(np.percentile(e, 95)),
            "max_m": float(np.max(e)),
            "ipin_score_m": ipin_score(e, f),
        }
    return table


def format_table(table: dict[str, dict[str, Any]], paper: bool) -> str:
    """The console table; the PDR row is labelled :data:`PDR_ROW_LABEL`."""
    labels = {n: PDR_ROW_LABEL if n == schemes.PDR_ONLY else n for n in table}
    w = max(11, *(len(v) + 1 for v in labels.values())) if labels else 11
    head = f"{'scheme':<{w}}{'n':>6}{'mean m':>9}{'p75 m':>8}{'p95 m':>8}{'max m':>8}{'ipin m':>8}"
    if paper:
        head += f"{'paper mean':>12}{'paper p75':>11}"
    lines = [head]
    for name, r in table.items():
        line = (
            f"{labels[name]:<{w}}{r['n']:>6}{r['mean_m']:>9.2f}{r['p75_m']:>8.2f}{r['p95_m']:>8.2f}"
            f"{r['max_m']:>8.2f}{r['ipin_score_m']:>8.2f}"
        )
        if paper:
            pm = PAPER.get(name)
            line += f"{pm[0]:>12.2f}{pm[1]:>11.2f}" if pm else f"{'-':>12}{'-':>11}"
        lines.append(line)
    return "\n".join(lines)


def run_aadr2015(
    seeds: list[int], paces: list[str], firmware: Firmware, out: Path, sets: Sequence[str]
) -> dict[str, Any]:
    t0 = time.perf_counter()
    console.say("bench aadr2015: survey and radio map")
    site = build_site("aadr2015_survey", firmware, out / "survey")
    pooled: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    runs = []
    n = len(seeds) * len(paces)
    for i, (pace, seed) in enumerate((p, s) for p in paces for s in seeds):
        scenario = "aadr2015" if pace == "normal" else f"aadr2015_{pace}"
        console.say(f"bench aadr2015: [{i + 1}/{n}] {scenario} seed {seed}")
        walk = out / f"{scenario}-s{seed}"
        simulate_and_log(scenario, seed, firmware, walk, site, sets)
        errors = score(walk, "waypoint", f"{scenario} seed {seed}, error at the reference points")
        runs.append(
            {
                "scenario": scenario,
                "seed": seed,
                "mean_m": {k: float(np.mean(e)) for k, (e, _) in errors.items() if e.size},
            }
        )
        for k, v in errors.items():
            pooled.setdefault(k, []).append(v)
    table = pooled_table(pooled)
    wifi, adaptive, kalman = (table.get(k, {}).get("mean_m") for k in ("wifi_only", "adaptive", "kalman"))
    reduction = None if not (wifi and adaptive) else 100.0 * (wifi - adaptive) / wifi
    doc = {
        "bench": "aadr2015",
        "seeds": seeds,
        "paces": paces,
        "sets": list(sets),
        "site": str(site),
        "table": table,
        "paper": PAPER,
        "runs": runs,
        "adaptive_reduction_pct": reduction,
        "targets": {"adaptive_reduction_pct_min": 43.0, "kalman_at_least_as_good_as_adaptive": True},
        "targets_met": {
            "adaptive_reduction": reduction is not None and reduction >= 43.0,
            "kalman_vs_adaptive": kalman is not None and adaptive is not None and kalman <= adaptive,
        },
        "run_s": time.perf_counter() - t0,
    }
    (out / "aadr2015.json").write_text(json.dumps(doc, indent=2) + "\n")
    return doc


def run_office(seeds: list[int], firmware: Firmware, out: Path, sets: Sequence[str]) -> dict[str, Any]:
    t0 = time.perf_counter()
    console.say("bench office-wifi: survey of both floors and radio map")
    site = build_site("office_survey", firmware, out / "survey")
    pooled: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    runs = []
    for i, seed in enumerate(seeds):
        console.say(f"bench office-wifi: [{i + 1}/{len(seeds)}] default seed {seed}")
        walk = out / f"default-s{seed}"
        simulate_and_log("default", seed, firmware, walk, site, sets)
        errors = score(walk, None, f"default seed {seed}, every scheme from its first fix")
        runs.append(
            {"seed": seed, "mean_m": {k: float(np.mean(e)) for k, (e, _) in errors.items() if e.size}}
        )
        for k, v in errors.items():
            pooled.setdefault(k, []).append(v)
    table = pooled_table(pooled)
    kalman = table.get("kalman", {})
    doc = {
        "bench": "office_wifi",
        "seeds": seeds,
        "sets": list(sets),
        "site": str(site),
        "table": table,
        "runs": runs,
        "targets": {"kalman_mean_m_max": 2.0, "kalman_p95_m_max": 4.5},
        "targets_met": {
            "kalman_mean": kalman.get("mean_m", 1e9) <= 2.0,
            "kalman_p95": kalman.get("p95_m", 1e9) <= 4.5,
        },
        "run_s": time.perf_counter() - t0,
    }
    (out / "office_wifi.json").write_text(json.dumps(doc, indent=2) + "\n")
    return doc


def _num(value: float | None, unit: str) -> str:
    return "n/a" if value is None else f"{value:.2f} {unit}"


def missed_targets_aadr2015(doc: dict[str, Any]) -> list[str]:
    """One line per target missed in an ``aadr2015.json`` document (empty when all are met)."""
    met, targets, table = doc["targets_met"], doc["targets"], doc["table"]
    mean = {k: table.get(k, {}).get("mean_m") for k in ("adaptive", "kalman")}
    lines = []
    if not met["adaptive_reduction"]:
        lines.append(
            f"aadr2015: adaptive's mean error reduction vs wifi_only = {_num(doc['adaptive_reduction_pct'], '%')} "
            f"(target >= {targets['adaptive_reduction_pct_min']} %)"
        )
    if not met["kalman_vs_adaptive"]:
        lines.append(
            f"aadr2015: kalman mean error = {_num(mean['kalman'], 'm')} "
            f"(target <= adaptive's {_num(mean['adaptive'], 'm')})"
        )
    return lines


def missed_targets_office(doc: dict[str, Any]) -> list[str]:
    """One line per target missed in an ``office_wifi.json`` document (empty when all are met)."""
    kalman, targets = doc["table"].get("kalman", {}), doc["targets"]
    lines = []
    for key, field, figure, target in (
        ("kalman_mean", "mean_m", "kalman mean error", targets["kalman_mean_m_max"]),
        ("kalman_p95", "p95_m", "kalman p95 error", targets["kalman_p95_m_max"]),
    ):
        if not doc["targets_met"][key]:
            lines.append(f"office-wifi: {figure} = {_num(kalman.get(field), 'm')} (target <= {target} m)")
    return lines
