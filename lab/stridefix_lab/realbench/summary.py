"""The results of ``realbench fusion``: per group and scheme the pooled error statistics, the learned
constants and the tuning choices of every fold, the JSON document and the console tables.

Per walk and per group, per scheme: n, mean, median, p75, p90, p95, max, RMSE, floor hit rate, IPIN
score = p75 of 2-D error + 15 m·|floor error|; the share of walks whose mean error exceeds
:data:`ROBUST_MEAN_M`. Scheme names and their order come from :mod:`stridefix_analyzer.schemes`.
Which source each fix came from: per walk (``walk_rows[].fix_sources``) and pooled per group
(``groups[].fix_sources``, and ``fix_sources_true_start`` with ``--true-start``), FIX records per
scheme and method (Wi-Fi, GNSS, BLE, landmark): offered, accepted, rejected, rejected by reason
(:mod:`stridefix_analyzer.scoring.fixsources`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from stridefix_analyzer import schemes
from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.radiomap.strides import error_stats, spread
from stridefix_analyzer.scoring.fixsources import format_fix_sources, merge_fix_source_counts
from stridefix_analyzer.scoring.metrics import IPIN_FLOOR_PENALTY_M, ipin_score

from stridefix_lab.realbench import reference
from stridefix_lab.realbench.fold import FoldJob
from stridefix_lab.realbench.tuning import Axis

#: a walk whose mean error exceeds this is a failure for the robustness share [m]
ROBUST_MEAN_M = 15.0
#: the row of pdr_only's truth-initialised run (--true-start), shown beside the first-fix table
PDR_TRUE_START_LABEL = f"{schemes.PDR_ONLY} (truth-initialised)"


def stats_of(errors: ArrayLike) -> dict[str, Any]:
    """n, mean, median, p75, p90, p95, max (:func:`stridefix_analyzer.radiomap.strides.error_stats`) and RMSE of the finite
    position errors [m] (distances, so never negative)."""
    e = np.asarray(errors, float)
    e = e[np.isfinite(e)]
    return {**error_stats(e), "rmse": float(np.sqrt(np.mean(e**2))) if len(e) else math.nan}


def _pooled_row(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """One scheme's (or reference's) walks pooled: sample stats, IPIN score, floor hit rate, walk means."""
    err = np.concatenate([np.asarray(r["errors_m"], float) for r in rows]) if rows else np.zeros(0)
    ferr = np.concatenate([np.asarray(r["floor_errors"], float) for r in rows]) if rows else np.zeros(0)
    means = np.array([r["mean"] for r in rows], float)
    finite = means[np.isfinite(means)]
    return {
        **stats_of(err),
        "ipin_score": ipin_score(err, ferr),
        "floor_hit_rate": float(np.mean(ferr == 0)) if len(ferr) else math.nan,
        "walks": len(rows),
        "walks_mean_over_15m": int(np.sum(finite > ROBUST_MEAN_M)),
        "share_walks_mean_over_15m": float(np.mean(finite > ROBUST_MEAN_M)) if len(finite) else math.nan,
        "walk_mean_median": float(np.median(finite)) if len(finite) else math.nan,
    }


def summarize_group(results: Sequence[Mapping[str, Any]], tag: str = "fixes") -> dict[str, Any]:
    """Per scheme over a group's walks: pooled sample stats, IPIN score, floor hit rate, the
    per-walk mean spread and the share of walks whose mean error exceeds :data:`ROBUST_MEAN_M`; the
    same for the textbook references (``references``) and the schemes that lose to them
    (``loses_to_reference``, :func:`loses_to_reference`)."""
    names = [n for n in schemes.NAMES if any(n in r.get(tag, {}) for r in results)]
    table = {name: _pooled_row([r[tag][name] for r in results if name in r.get(tag, {})]) for name in names}
    refs = {}
    for name in reference.NAMES:
        rows = [r["references"][tag][name] for r in results if name in r.get("references", {}).get(tag, {})]
        if rows:
            refs[name] = _pooled_row(rows)
    w, a = table.get("wifi_only", {}).get("mean"), table.get("adaptive", {}).get("mean")
    red = 100.0 * (w - a) / w if w and a is not None and math.isfinite(w) and w > 0 else math.nan
    return {
        "schemes": table,
        "adaptive_vs_wifi_only_reduction_pct": red,
        "references": refs,
        "loses_to_reference": loses_to_reference(table, refs),
    }


def primary_scheme(summary: Mapping[str, Any], jobs: Sequence[FoldJob]) -> dict[str, Any]:
    """The scheme of the product's primary pose (what ``POSE`` carries) in a group's replays: the
    multi-scheme controller's when it ran, with the fusion scheme it followed in how many folds (the
    fold site's choice), else the copy of ``controller.init_scheme``'s pose (its ``--set``, else the
    firmware's default). ``scheme`` names the row of the summary tables."""
    if schemes.CONTROLLER in summary["schemes"]:
        follows: dict[str, int] = {}
        for j in jobs:
            v = j.variants.get("lsd")
            if v is not None:
                follows[v] = follows.get(v, 0) + 1
        return {"scheme": schemes.CONTROLLER, "follows": follows}
    init = next(
        (
            kv.split("=", 1)[1].strip()
            for j in jobs
            for kv in j.param_sets
            if kv.split("=", 1)[0].strip() == INIT_KEY
        ),
        None,
    )
    if init is None and jobs:
        init = jobs[0].firmware.params[INIT_KEY].default
    name = schemes.scheme_name(int(init)) if init is not None and init.lstrip("-").isdigit() else init
    return {"scheme": name, "follows": {}}


def primary_text(summary: Mapping[str, Any]) -> str:
    """One line on the primary pose: its row, what it followed, and how far it is from the best
    fused scheme by IPIN score and mean."""
    pr = summary["primary"]
    table = summary["schemes"]
    follows = ", ".join(f"{v} in {n} folds" for v, n in pr.get("follows", {}).items())
    text = f"primary pose (POSE): {pr['scheme']}" + (f", following {follows}" if follows else "")
    row = table.get(pr["scheme"])
    fused = {n: r for n, r in table.items() if schemes.is_fused(n)}
    if row and fused:
        for metric in LOSS_METRICS:
            best = min(fused, key=lambda n: fused[n][metric])
            text += f"; {metric} {_f(row[metric])} vs best fused {best} {_f(fused[best][metric])}"
    return text


#: the firmware parameter naming the scheme POSE copies without a context map
INIT_KEY = "controller.init_scheme"


#: which reference a scheme is held against: pdr_only against the plain PDR; every scheme that fuses
#: fixes with steps against the EKF (wifi_only fuses nothing: it has no reference)
REFERENCE_OF = {schemes.PDR_ONLY: reference.REFERENCE_PDR, schemes.WIFI_ONLY: None}
LOSS_METRICS = ("ipin_score", "mean")


def loses_to_reference(
    table: Mapping[str, Mapping[str, Any]], refs: Mapping[str, Mapping[str, Any]]
) -> list[dict[str, Any]]:
    """The schemes whose IPIN score and mean error [m] are both worse (higher) than their reference's
    (:data:`REFERENCE_OF`, else ``reference_ekf``): scheme, reference and both metrics with both values."""
    out = []
    for name, row in table.items():
        ref = REFERENCE_OF.get(name, reference.REFERENCE_EKF)
        if ref is None or ref not in refs:
            continue
        lost = {k: {"scheme": row[k], "reference": refs[ref][k]} for k in LOSS_METRICS}
        if all(math.isfinite(v["reference"]) and v["scheme"] > v["reference"] for v in lost.values()):
            out.append({"scheme": name, "reference": ref, "lost": lost})
    return out


def loses_text(summary: Mapping[str, Any]) -> str:
    """One line: which schemes lose to their reference (console and HTML)."""
    lost = summary.get("loses_to_reference", [])
    if not summary.get("references"):
        return "loses to reference: no reference ran"
    if not lost:
        return "loses to reference: none"
    return "LOSES TO REFERENCE: " + "; ".join(
        f"{e['scheme']} vs {e['reference']} ("
        + ", ".join(f"{k} {_f(v['scheme'])} > {_f(v['reference'])}" for k, v in e["lost"].items())
        + ")"
        for e in lost
    )


def build_doc(
    fmt: str,
    dirs: Sequence[Any],
    labels: Sequence[str],
    group_info: Mapping[str, dict[str, Any]],
    walks: Sequence[Mapping[str, Any]],
    results: Sequence[Mapping[str, Any]],
    job_of: Mapping[str, FoldJob],
    axes: Sequence[Axis],
    true_start: bool,
) -> dict[str, Any]:
    """The JSON document: per group its info, scheme summaries, fold constants and walk rows."""
    per_group = []
    for label in labels:
        info = group_info[label]
        rs = [r for r in results if r["group"] == label]
        jobs = [job_of[r["walk"]] for r in rs]
        entry = {**info, "summary": summarize_group([r for r in rs if not r["error"]], "fixes")}
        entry["summary"]["primary"] = primary_scheme(entry["summary"], jobs)
        if true_start:
            entry["summary_true_start"] = summarize_group([r for r in rs if not r["error"]], "true_start")
            entry["summary_true_start"]["primary"] = primary_scheme(entry["summary_true_start"], jobs)
        entry["fold_errors"] = [{"walk": r["walk"], "error": r["error"]} for r in rs if r["error"]]
        for tag, key in (("fixes", "fix_sources"), ("true_start", "fix_sources_true_start")):
            if tag == "fixes" or true_start:
                entry[key] = merge_fix_source_counts(
                    r["fix_sources"][tag] for r in rs if not r["error"] and tag in r.get("fix_sources", {})
                )
        folds = [r["fold"] for r in rs if r.get("fold")]
        entry["constants"] = {
            "K": spread([f["K"] for f in folds]),
            "rotation_deg": spread([f["rotation_deg"] for f in folds]),
            "n_rp": spread([f["n_rp"] for f in folds]),
            "n_ap": spread([f["n_ap"] for f in folds]),
            **{
                key: {
                    v: sum(1 for f in folds if f.get(key) == v)
                    for v in sorted({f.get(key) for f in folds} - {None})
                }
                for key in (f"{a.name}_variant" for a in axes)
            },
        }
        entry["walk_rows"] = []
        for r in rs:
            j = job_of[r["walk"]]
            w = walks[j.index]
            row = {
                "walk": r["walk"],
                "error": r["error"],
                "fold": r.get("fold"),
                "rotation_learned": j.rotation_learned,
                "waypoints": len(w["waypoint_t_us"]),
                "steps_nosite": len(w["step_t_us"]),
                "duration_s": (w["import"] or {}).get("duration_s"),
                "floors": w["floors"],
                "dir": str(j.dir),
            }
            for tag in ("fixes", "true_start"):
                if tag in r:
                    row[tag] = r[tag]
            row["references"] = r.get("references", {})
            row["fix_sources"] = r.get("fix_sources", {}).get("fixes", {})
            entry["walk_rows"].append(row)
        per_group.append(entry)
    return {
        "benchmark": "realbench fusion (leave one walk out)",
        "format": fmt,
        "inputs": [str(d) for d in dirs],
        "true_start": true_start,
        "groups": per_group,
    }


def strip_samples(doc: Mapping[str, Any]) -> dict[str, Any]:
    """The JSON keeps per-walk statistics; per-sample errors stay in each walk's analysis.npz."""
    out = json.loads(json.dumps(json_ready(doc)))
    for g in out["groups"]:
        for row in g["walk_rows"]:
            runs = [row.get(tag) or {} for tag in ("fixes", "true_start")]
            runs += list((row.get("references") or {}).values())
            for run in runs:
                for s in run.values():
                    s.pop("errors_m", None)
                    s.pop("floor_errors", None)
    return out


#: the wall-clock timers of a results.json (the run's phases, a fold's site content, its floor-plan
#: survey) and how the run was scheduled (``params.jobs``, ``params.scheduler``): not results
TIMERS = ("run_s", "content_content_s", "survey_s")
HOW_RUN = ("jobs", "scheduler")


def untimed(doc: Any) -> Any:
    """``doc`` (a results.json document) without :data:`TIMERS` and ``params``' :data:`HOW_RUN`: what
    must be identical on every scheduler."""
    if isinstance(doc, Mapping):
        return {
            k: ({p: untimed(q) for p, q in v.items() if p not in HOW_RUN} if k == "params" else untimed(v))
            for k, v in doc.items()
            if k not in TIMERS
        }
    if isinstance(doc, list):
        return [untimed(v) for v in doc]
    return doc


def pdr_true_start(group: Mapping[str, Any]) -> dict[str, Any] | None:
    """pdr_only's row of a group's truth-initialised run; None when it was not run (no --true-start)."""
    return group.get("summary_true_start", {}).get("schemes", {}).get(schemes.PDR_ONLY)


def pdr_true_start_text(fmt: str, group: Mapping[str, Any]) -> str:
    """One line on pdr_only from the true start in a group of data set ``fmt`` (console and HTML)."""
    r = pdr_true_start(group)
    head = f"[{fmt}] {group['label']}: {schemes.PDR_ONLY} from the TRUE START (truth-initialised)"
    if r is None:
        return f"{head}: not run (realbench --true-start runs it)"
    return (
        f"{head}: mean {_f(r['mean'])} m, p75 {_f(r['p75'])} m, IPIN score {_f(r['ipin_score'])} m, "
        f"floor hit {_f(100 * r['floor_hit_rate'], 1)} % ({r['n']} samples, {r['walks']} walks)"
    )


# --- console ---------------------------------------------------------------------------------------


def _f(v: Any, d: int = 2) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{d}f}"


def format_tables(doc: Mapping[str, Any], axes: Sequence[Axis]) -> str:
    """Per group: scheme × n, mean, median, p75, p90, max, RMSE, IPIN, floor %, walks > 15 m; under the
    first-fix table pdr_only's truth-initialised row (:data:`PDR_TRUE_START_LABEL`) and its line."""
    lines = []
    for g in doc["groups"]:
        c = g["constants"]
        lines.append(
            f"{g['label']}: {g['walks']} walks ({g['ran']} ran, "
            f"{len(g['walk_rows']) - len(g['fold_errors'])} scored), leave one walk out; "
            f"K {_f(c['K']['mean'], 3)} ({_f(c['K']['min'], 3)}..{_f(c['K']['max'], 3)}), "
            f"rotation {_f(c['rotation_deg']['mean'], 1)} deg "
            f"({_f(c['rotation_deg']['min'], 1)}..{_f(c['rotation_deg']['max'], 1)}), "
            + "".join(
                f"{a.label} "
                + ", ".join(f"{v} in {n} folds" for v, n in c.get(f"{a.name}_variant", {}).items())
                + ", "
                for a in axes
            )
            + f"map {_f(c['n_rp']['mean'], 0)} RPs / {_f(c['n_ap']['mean'], 0)} APs"
        )
        for key, title in (
            ("summary", "every scheme from its first fix"),
            ("summary_true_start", "TRUTH-INITIALISED start"),
        ):
            if key not in g:
                continue
            s = g[key]
            rows = list(s["schemes"].items())
            true_pdr = pdr_true_start(g)
            if key == "summary" and true_pdr is not None:
                rows.append((PDR_TRUE_START_LABEL, true_pdr))
            w = max(
                [10, *(len(name) + 1 for name, _ in rows), *(len(n) + 1 for n in s.get("references", {}))]
            )
            lines.append(f"  [{title}]  errors in m at the ground-truth times")
            lines.append(
                f"  {'scheme':<{w}}{'n':>6}{'mean':>8}{'median':>8}{'p75':>8}{'p90':>8}"
                f"{'max':>8}{'rmse':>8}{'ipin':>8}{'floor%':>8}{'>15m':>10}"
            )
            refs = list(s.get("references", {}).items())
            losers = {e["scheme"]: e["reference"] for e in s.get("loses_to_reference", [])}
            for i, (name, r) in enumerate([*rows, *refs]):
                if refs and i == len(rows):
                    lines.append("  -- textbook references, computed in Python (not schemes) --")
                share = r["share_walks_mean_over_15m"]
                lines.append(
                    f"  {name:<{w}}{r['n']:>6}{_f(r['mean']):>8}{_f(r['median']):>8}"
                    f"{_f(r['p75']):>8}{_f(r['p90']):>8}{_f(r['max']):>8}{_f(r['rmse']):>8}"
                    f"{_f(r['ipin_score']):>8}{_f(100 * r['floor_hit_rate'], 1):>8}"
                    f"{(_f(100 * share, 1) + '%') if share == share else '-':>10}"
                    + (f"  loses to {losers[name]}" if name in losers and i < len(s["schemes"]) else "")
                )
            lines.append(
                f"  adaptive vs wifi_only: mean error reduced by "
                f"{_f(s['adaptive_vs_wifi_only_reduction_pct'], 1)} %  (>15m = share of walks "
                f"whose mean error exceeds {ROBUST_MEAN_M:g} m; ipin = p75 of 2-D error + "
                f"{IPIN_FLOOR_PENALTY_M:g} m x |floor error|, Matlab quantile)"
            )
            lines.append(f"  {loses_text(s)}")
            if s.get("primary"):
                lines.append(f"  {primary_text(s)}")
        lines.append(f"  {pdr_true_start_text(doc['format'], g)}")
        if "fix_sources" in g:
            text = format_fix_sources(g["fix_sources"], "pooled over the walks")
            lines.append("  " + text.replace("\n", "\n  "))
        for e in g["failed"] + g["fold_errors"]:
            lines.append(f"  failed {e['walk']}: {e['error']}")
    return "\n".join(lines)
