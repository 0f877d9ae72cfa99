"""``stridefix-lab bench controller``: the multi-scheme controller against every fixed scheme on the SIL
``campus2`` walks (Jäger, Süß, Becker §III-B/C): outdoors → building A's door → stairs →
floor 1 → elevator → floor 2 → elevator → out → the path → building B's door.

The campus is surveyed once (``campus2_survey``, its own seed), the survey replayed through
stridefixd and the radio-map builder (:func:`stridefix_analyzer.radiomap.make.make_site`) makes the site with its context map. Then for
each seed the ``campus2`` walk is simulated once and replayed through the real stridefixd twice: with
the controller (the default configuration) and with ``controller.enabled=0`` (the fixed schemes
alone, the baseline rows: in the controller's run the policy switches sources off for every scheme).
Per seed and pooled over the seeds (figures in :mod:`.controller_score`):

* mean and p75 error per TRUE context (truth x, y, floor and the site's building outlines) and over
  the whole walk, for the controller (POSE scheme ``controller`` of its run) and every fixed scheme
  (of the baseline run); the floor hit rate of each;
* the latency of each transition (the simulator's crossing time → the first switch into the new
  context; missed after 30 s) and the false switches;
* the power proxy: seconds with GNSS, Wi-Fi and BLE on (the controller's HEALTH; a fixed scheme keeps
  every radio on the whole walk: the baseline run's HEALTH, or the walk's span);
* the controller's CONTEXT events per rule, and a timeline PNG per seed (truth vs controller).

Targets, each in the JSON's ``targets`` with its value and met: controller mean error ≤
the best fixed scheme's in every context; ≥ 20 % below the best single fixed scheme over the whole
walk; floor hit ≥ 99 %; every transition detected within 5 s; no false switch.
"""

from __future__ import annotations

import argparse
import json
import time
import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix import pose_t
from stridefix_analyzer import console, schemes
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import read_table
from stridefix_analyzer.io.sitefile import SiteFileError, read_site
from stridefix_analyzer.scoring import targets as target_rows
from stridefix_analyzer.scoring.analyze import run_analyze
from stridefix_analyzer.scoring.context import context_summary, rule_name
from stridefix_analyzer.scoring.metrics import scored_errors

from stridefix_lab.bench import controller_score as cs
from stridefix_lab.bench import fusion
from stridefix_lab.bench.controller_plot import write_timeline
from stridefix_lab.bench.registry import Bench
from stridefix_lab.bench.sil_pdr import BenchError
from stridefix_lab.stages import replay, simulate

SCENARIO, SURVEY = "campus2", "campus2_survey"
CONTROLLER = schemes.scheme_name(pose_t.SCHEME_CONTROLLER)
#: the baseline replay: the fixed schemes alone
BASELINE_SETS = ("controller.enabled=0",)
#: the targets
WHOLE_REDUCTION_MIN = 0.20  # controller ≥ 20 % below the best single fixed scheme over the whole walk
FLOOR_HIT_MIN = 0.99
WHOLE = "whole walk"
RADIOS = ("gnss", "wifi", "ble")


def outlines_of(site: Path, building: Path) -> tuple[list[cs.Outline], list[str]]:
    """The buildings' outlines and the site's building names (index order, as CONTEXT numbers them):
    from the site's context map, else from the building description's [[building]] tables."""
    try:
        s = read_site(site)
        names = list(getattr(s, "building_name", []))
    except SiteFileError as exc:
        raise BenchError(f"{site}: {exc}") from exc
    if names:
        xb = np.asarray(s.outline_building, np.int64)
        xy = np.column_stack([np.asarray(s.outline_x_m, float), np.asarray(s.outline_y_m, float)])
        return [cs.Outline(n, xy[xb == i]) for i, n in enumerate(names)], names
    doc = tomllib.loads(building.read_text(encoding="utf-8"))
    out = [cs.Outline(str(b["name"]), np.asarray(b["outline"], float)) for b in doc.get("building", [])]
    return out, [o.name for o in out]


def build_site(firmware: Firmware, out: Path) -> Path:
    """Survey → site file with the survey's building description (the context map)."""
    return fusion.build_site(SURVEY, firmware, out, out / "building.toml")


def _scheme_rows(metrics: Any, outlines: Sequence[cs.Outline], only: str | None = None) -> dict[str, Any]:
    """Per scheme of one analysis: errors by true context and floor hits (0/1 per scored sample)."""
    rows = {}
    for s in metrics.schemes.values():
        if only is not None and s.name != only:
            continue
        if only is None and s.name == CONTROLLER:
            continue
        m = s.match
        keys = cs.truth_contexts(m["truth_x_m"], m["truth_y_m"], m["truth_floor"], outlines)
        _, floor_err = scored_errors(m)
        rows[s.name] = {
            "errors": cs.errors_by_context(keys, m["error_m"]),
            "floor_hits": (floor_err == 0).astype(int).tolist(),
        }
    return rows


def _span_s(truth: Any) -> float:
    """The truth's time span [s]."""
    return float((truth["t_us"][-1] - truth["t_us"][0]) / 1e6) if len(truth) else 0.0


def score_walk(
    walk: Path, summary: dict[str, Any], outlines: list[cs.Outline], names: list[str]
) -> dict[str, Any]:
    """One seed's figures (module docstring) from its two replays."""
    truth_log = str(walk / "truth.lcmlog")
    ctl_sum, ctl = run_analyze([str(walk / "stridefixd.lcmlog"), truth_log], str(walk), label="controller")
    base_sum, base = run_analyze(
        [str(walk / "fixed" / "stridefixd.lcmlog"), truth_log], str(walk / "fixed"), label="fixed schemes"
    )
    rows = _scheme_rows(base, outlines)
    rows.update(_scheme_rows(ctl, outlines, only=CONTROLLER))
    truth = ctl.truth
    tkeys = cs.truth_contexts(truth["x_m"], truth["y_m"], truth["floor"], outlines)
    try:
        transitions, source = cs.sim_transitions(summary), "sim_summary.json"
    except cs.TransitionsError:
        transitions, source = (
            cs.truth_transitions(truth["t_us"], tkeys),
            "truth timeline (no sim transitions)",
        )
    ctx = read_table(walk / "stridefixd.lcmlog", "CONTEXT")
    if ctx is not None and len(ctx):
        keys = cs.controller_keys(ctx["kind"], ctx["building"], ctx["floor"], names)
        sw = np.flatnonzero(ctx["switched"].astype(bool))
        sw_t = ctx["t_us"][sw]
        sw_keys = [keys[i] for i in sw]
        sw_rules = [rule_name(int(r)) for r in ctx["rule"][sw]]
        ctl_line = (ctx["t_us"].tolist(), keys)
    else:
        sw_t, sw_keys, sw_rules, ctl_line = np.zeros(0, np.int64), [], [], ([], [])
    section = context_summary(ctx, ctl_sum.get("health") or {}, int(truth["t_us"][-1]))
    span = _span_s(truth)
    ctl_health = ctl_sum.get("health") or {}
    base_health = base_sum.get("health") or {}
    power = {
        CONTROLLER: {r: ctl_health.get(f"{r}_on_s") for r in RADIOS},
        "fixed": {r: float(base_health.get(f"{r}_on_s") or span) for r in RADIOS},
    }
    return {
        "rows": rows,
        "transitions_from": source,
        "transitions": cs.latencies(transitions, sw_t, sw_keys),
        "switches": cs.false_switches(transitions, sw_t, sw_keys, truth["t_us"], tkeys, sw_rules),
        "events_by_rule": (section or {}).get("events_by_rule", {}),
        "switches_by_rule": (section or {}).get("switches_by_rule", {}),
        "power_s": power,
        "duration_s": span,
        "_truth_line": cs.timeline(truth["t_us"], tkeys),
        "_ctl_line": ctl_line,
    }


def _stats(v: list[float]) -> dict[str, Any]:
    a = np.asarray(v, float)
    if a.size == 0:
        return {"n": 0, "mean_m": None, "p75_m": None}
    return {"n": int(a.size), "mean_m": float(a.mean()), "p75_m": float(np.percentile(a, 75))}


def pool(walks: Sequence[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Scheme → {context → n, mean, p75}, floor hit rate: pooled over the walks (controller first)."""
    names = {n for w in walks for n in w["rows"]}
    fixed = fusion.scheme_order([n for n in names if n != CONTROLLER])
    table: dict[str, dict[str, Any]] = {}
    for name in [CONTROLLER, *fixed]:
        rows = [w["rows"][name] for w in walks if name in w["rows"]]
        if not rows:
            continue
        contexts = sorted({c for r in rows for c in r["errors"]} - {WHOLE}) + [WHOLE]
        hits: list[int] = sum((r["floor_hits"] for r in rows), [])
        table[name] = {
            "contexts": {c: _stats(sum((r["errors"].get(c, []) for r in rows), [])) for c in contexts},
            "floor_hit_rate": float(np.mean(hits)) if hits else None,
        }
    return table


def _mean(table: dict[str, dict[str, Any]], name: str, ctx: str) -> float | None:
    v = table.get(name, {}).get("contexts", {}).get(ctx, {}).get("mean_m")
    return None if v is None else float(v)


def targets(
    table: dict[str, dict[str, Any]],
    transitions: Sequence[dict[str, Any]],
    switches: Sequence[dict[str, Any]],
    n_seeds: int,
) -> list[dict[str, Any]]:
    """The campus targets, each with its value and met (a missing controller misses all)."""
    rows = []
    fixed = [n for n in table if n != CONTROLLER]
    contexts = sorted({c for n in table for c in table[n]["contexts"]} - {WHOLE})
    for c in contexts:
        best = min(((m, n) for n in fixed if (m := _mean(table, n, c)) is not None), default=(None, None))
        v = _mean(table, CONTROLLER, c)
        rows.append(
            {
                "figure": f"controller mean error in {c}",
                "value": v,
                "target": f"<= best fixed ({best[1]}: {best[0]:.2f} m)"
                if best[0] is not None
                else "<= best fixed",
                "met": v is not None and best[0] is not None and v <= best[0],
            }
        )
    best_w = min(((m, n) for n in fixed if (m := _mean(table, n, WHOLE)) is not None), default=(None, None))
    v = _mean(table, CONTROLLER, WHOLE)
    bound = None if best_w[0] is None else (1.0 - WHOLE_REDUCTION_MIN) * best_w[0]
    rows.append(
        {
            "figure": "controller mean error over the whole walk",
            "value": v,
            "target": f"<= {bound:.2f} m (20 % below {best_w[1]}'s {best_w[0]:.2f} m)"
            if bound is not None
            else "",
            "met": v is not None and bound is not None and v <= bound,
        }
    )
    fh = table.get(CONTROLLER, {}).get("floor_hit_rate")
    rows.append(
        {
            "figure": "controller floor hit rate",
            "value": fh,
            "target": f">= {FLOOR_HIT_MIN}",
            "met": fh is not None and fh >= FLOOR_HIT_MIN,
        }
    )
    lats = [t["latency_s"] for t in transitions if t["latency_s"] is not None]
    late = [t for t in transitions if not t["within_target"]]
    worst = f"{max(lats):.1f} s" if lats else "-"
    rows.append(
        {
            "figure": f"transitions detected within {cs.LATENCY_TARGET_S:g} s ({len(transitions)} transitions)",
            "value": len(transitions) - len(late),
            "target": f"all {len(transitions)} (worst {worst}, {len(transitions) - len(lats)} missed)",
            "met": bool(transitions) and not late,
        }
    )
    n_false = sum(1 for s in switches if s["false"])
    rows.append(
        {
            "figure": f"false switches in {n_seeds} seeds",
            "value": n_false,
            "target": f"0 (of {len(switches)} switches; none at all is a miss)",
            "met": n_false == 0 and bool(switches),
        }
    )
    return rows


def run_controller(seeds: list[int], firmware: Firmware, out: Path, sets: Sequence[str]) -> dict[str, Any]:
    """The bench (module docstring); writes ``out.parent/controller.json`` and the PNGs in ``out``."""
    t0 = time.perf_counter()
    console.say("bench controller: campus2 survey and site (context map)")
    site = build_site(firmware, out / "survey")
    outlines, names = outlines_of(site, out / "survey" / "building.toml")
    walks, per_seed, pngs = [], [], []
    for i, seed in enumerate(seeds):
        walk = out / f"{SCENARIO}-s{seed}"
        summary = simulate(SCENARIO, seed, walk, f"sim {SCENARIO} seed {seed}", BenchError)
        for log_dir, extra in ((walk, ()), (walk / "fixed", BASELINE_SETS)):
            log_dir.mkdir(parents=True, exist_ok=True)
            replay(
                firmware,
                f"stridefixd {SCENARIO} seed {seed}{' (fixed schemes)' if extra else ''}",
                BenchError,
                input=walk / "board.candump",
                log=log_dir / "stridefixd.lcmlog",
                site=site,
                sets=[*sets, *extra],
            )
        w = score_walk(walk, summary, outlines, names)
        png = out / f"timeline-s{seed}.png"
        write_timeline(png, w["_truth_line"], w["_ctl_line"], w["transitions"], f"{SCENARIO} seed {seed}")
        pngs.append(str(png))
        walks.append(w)
        one = pool([w])
        per_seed.append(
            {
                "seed": seed,
                "table": one,
                **{k: v for k, v in w.items() if k not in ("rows",) and not k.startswith("_")},
            }
        )
        ctl = _mean(one, CONTROLLER, WHOLE)
        console.say(
            f"bench controller: [{i + 1}/{len(seeds)}] seed {seed}: controller whole walk "
            f"{'-' if ctl is None else f'{ctl:.2f} m'}, {sum(t['within_target'] for t in w['transitions'])}/"
            f"{len(w['transitions'])} transitions within {cs.LATENCY_TARGET_S:g} s, "
            f"{sum(s['false'] for s in w['switches'])} false switches"
        )
    table = pool(walks)
    transitions = [dict(t, seed=p["seed"]) for p in per_seed for t in p["transitions"]]
    switches = [dict(s, seed=p["seed"]) for p in per_seed for s in p["switches"]]
    power = {
        who: {r: float(sum((w["power_s"][who][r] or 0.0) for w in walks)) for r in RADIOS}
        for who in (CONTROLLER, "fixed")
    }
    rules: dict[str, int] = {}
    for w in walks:
        for k, v in w["events_by_rule"].items():
            rules[k] = rules.get(k, 0) + v
    doc = {
        "bench": "controller",
        "scenario": SCENARIO,
        "seeds": seeds,
        "sets": list(sets),
        "site": str(site),
        "buildings": names,
        "table": table,
        "transitions": transitions,
        "latency_s": _latency_stats(transitions),
        "switches": switches,
        "false_switches": sum(1 for s in switches if s["false"]),
        "power_s": power,
        "duration_s": float(sum(w["duration_s"] for w in walks)),
        "events_by_rule": dict(sorted(rules.items())),
        "per_seed": per_seed,
        "timelines": pngs,
        "targets": targets(table, transitions, switches, len(seeds)),
        "run_s": time.perf_counter() - t0,
    }
    out.mkdir(parents=True, exist_ok=True)
    (out.parent / "controller.json").write_text(json.dumps(doc, indent=1, allow_nan=False) + "\n")
    return doc


def _latency_stats(transitions: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Latency [s] per transition kind (door, stairs, elevator) and overall: n, detected, mean, max."""
    out = {}
    for kind in sorted({t["kind"] for t in transitions}) + ["all"]:
        rows = [t for t in transitions if kind in ("all", t["kind"])]
        lat = [t["latency_s"] for t in rows if t["latency_s"] is not None]
        out[kind] = {
            "n": len(rows),
            "detected": len(lat),
            "mean_s": float(np.mean(lat)) if lat else None,
            "max_s": float(np.max(lat)) if lat else None,
        }
    return out


def _f(v: float | None, w: int = 7) -> str:
    return f"{'-':>{w}}" if v is None else f"{v:>{w}.2f}"


def format_table(doc: dict[str, Any]) -> str:
    """The console summary: errors per true context, floor hit, latencies, switches, power, targets."""
    t = doc["table"]
    contexts = sorted({c for r in t.values() for c in r["contexts"]} - {WHOLE}) + [WHOLE]
    w = max(12, *(len(n) + 1 for n in t)) if t else 12
    cw = max(9, *(len(c) + 2 for c in contexts))
    lines = [
        f"campus2 walks, seeds {doc['seeds']}: mean error [m] per true context (p75 below in the JSON)",
        f"{'scheme':<{w}}" + "".join(f"{c:>{cw}}" for c in contexts) + f"{'floor%':>8}",
    ]
    for name, r in t.items():
        fh = r["floor_hit_rate"]
        lines.append(
            f"{name:<{w}}"
            + "".join(_f(r["contexts"].get(c, {}).get("mean_m"), cw) for c in contexts)
            + f"{'-' if fh is None else f'{100 * fh:.1f}':>8}"
        )
    lat = doc["latency_s"]
    lines.append(
        "latency [s] (crossing -> switch): "
        + "; ".join(
            f"{k} {v['detected']}/{v['n']} detected, mean {_f(v['mean_s'], 0).strip()}, max {_f(v['max_s'], 0).strip()}"
            for k, v in lat.items()
        )
    )
    falses = [s for s in doc["switches"] if s["false"]]
    lines.append(
        f"switches: {len(doc['switches'])}, false {len(falses)}"
        + "".join(
            f"\n  false: seed {s['seed']} t_us {s['t_us']} -> {s['to']} ({s['rule']}): {s['why']}"
            for s in falses[:10]
        )
    )
    p = doc["power_s"]
    lines.append(
        "radios on [s] (controller / fixed schemes): "
        + ", ".join(f"{r} {p[CONTROLLER][r]:.0f} / {p['fixed'][r]:.0f}" for r in RADIOS)
        + f"; CONTEXT events by rule: {doc['events_by_rule']}"
    )
    lines += target_rows.table_lines(doc["targets"])
    return "\n".join(lines)


def missed_targets(doc: dict[str, Any]) -> list[str]:
    """One line per missed target (figure, value, target)."""
    return target_rows.missed_lines("controller", doc["targets"])


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    doc = run_controller(seeds, firmware, out / "controller", args.sets)
    print(format_table(doc))
    print(f"wrote {out / 'controller.json'} and {len(doc['timelines'])} timelines ({doc['run_s']:.0f} s)")
    return missed_targets(doc)


BENCH = Bench(
    "controller",
    "the multi-scheme controller against every fixed scheme on the campus2 walks (error per true "
    "context, floor hit, transition latency, false switches, radios on)",
    _run,
    seeds="1,2,3,4,5,6,7,8,9,10",
    in_make_bench=True,
)
