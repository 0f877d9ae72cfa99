"""``stridefix-lab realbench crowd-map``: the fix error on a radio map nobody surveyed, next to the surveyed one.

The crowd-built map (Kannan 2024, §4-5: a radio map from crowd walks with anchors every 4th waypoint).
The walks, groups and folds are those of ``realbench fusion`` (:mod:`.fusion`: leave one walk out per
floor) and so are its phases 1-2 (:func:`.fusion.prepare_walks`, :func:`.fusion.plan_group`). Each
fold then gets two sites from its training walks:

* **truth map**: exactly the fold site ``realbench fusion`` builds (scan positions interpolated on the
  surveyed waypoints);
* **crowd map**: identical (same rotation, floors, walls, geo-reference, chosen settings, firmware
  ``--set``) except that each training walk's scan positions are its graph-solved positions
  (:func:`~stridefix_analyzer.crowd.graph_run.solve_walks_graph`: every K-th waypoint an anchor, the
  walk's site-less STEP stream between them, no Wi-Fi rows; :func:`~stridefix_analyzer.crowd.sites.
  solved_truth`), solved with what the fold's training walks' anchors teach: the heading variant they
  agree on and its fleet priors (:mod:`.crowdfolds`). Without Wi-Fi rows each walk's solve reads no
  other walk's scans; folds that learned the same share one solve per walk (no leak between folds:
  the held-out walk's anchors never enter its fold's choice).

The held-out walk is replayed on each (:func:`.fold.run_fold`, the same protocol) and scored at its
waypoints; the crowd positions' own error at the non-anchor waypoints is reported next to that of the
anchors interpolated in time. Outputs: ``results.json`` (``benchmark: crowd-map``) and the per-fold
work folders (``<walk>`` for the truth map, ``<walk>/crowd-map`` for the crowd map).
"""

from __future__ import annotations

import collections
import dataclasses
import math
import os
import sys
import time
from collections.abc import Mapping, Sequence
from typing import Any, TextIO

from stridefix_analyzer.console import Progress
from stridefix_analyzer.datasets.protocol import WalkGroup
from stridefix_analyzer.io.results import write_crowd_map_results
from stridefix_analyzer.radiomap.build import WalkStats

from stridefix_lab.realbench.crowdfolds import Choice, CrowdJob, choice_doc, fold_stats, solve_folds
from stridefix_lab.realbench.fold import STATS_KEYS, FoldJob, run_fold
from stridefix_lab.realbench.fusion import FusionConfig, Run, plan_group, prepare_walks, start_run
from stridefix_lab.realbench.summary import summarize_group

#: the schemes the console table shows (the JSON has every scheme): the Wi-Fi fix itself, and the ekf
SHOWN = ("wifi_only", "ekf")
MAPS = ("truth_map", "crowd_map")


@dataclasses.dataclass(frozen=True)
class CrowdMapConfig:
    """``realbench crowd-map``: the fusion run's options plus the crowd solve's."""

    fusion: FusionConfig
    anchors: str = "every:4"
    solver: str = "auto"
    #: scans whose solved position's posterior σ exceeds this [m] stay out of the crowd map (inf: none)
    max_sigma_m: float = math.inf


def _pair(jobs: tuple[FoldJob, FoldJob]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Both replays of one fold (truth map, crowd map), in one worker."""
    return run_fold(jobs[0]), run_fold(jobs[1])


def run_crowd_map(cc: CrowdMapConfig) -> dict[str, Any]:
    """Run the benchmark (module docstring); write ``cc.fusion.out_json``; return the document."""
    t_start = time.perf_counter()
    cfg = dataclasses.replace(cc.fusion, true_start=False, report=False)
    with start_run(dataclasses.replace(cfg, quiet=True)) as (run, groups):  # fusion's progress: silent
        return _run_crowd_map(cc, cfg, run, groups, t_start)


def _run_crowd_map(
    cc: CrowdMapConfig, cfg: FusionConfig, run: Run, groups: list[WalkGroup], t_start: float
) -> dict[str, Any]:
    stream = open(os.devnull, "w") if cfg.quiet else sys.stderr
    print(
        f"realbench: crowd-map: preparing {sum(len(g.walks) for g in groups)} walks", file=stream, flush=True
    )
    walks, parts = prepare_walks(run, groups)  # phase 1
    print(
        f"realbench: crowd-map: choosing the folds' settings of {len(parts)} groups", file=stream, flush=True
    )
    planned = [plan_group(run, p, walks) for p in parts]  # phase 2
    t_plan = time.perf_counter()
    crowd_jobs = {
        i: CrowdJob(
            w["walk"],
            tuple(w["fw_logs"].items()),
            w["import_log"],
            cc.anchors,
            cc.solver,
            run.cfg.cell_size_m,
            cc.max_sigma_m,
        )
        for i, w in enumerate(walks)
        if not w["error"]
    }
    folds: dict[int, list[int]] = {}
    for _, jobs in planned:
        ids = [j.index for j in jobs]
        folds |= {j.index: [i for i in ids if i != j.index and i in crowd_jobs] for j in jobs}
    variants = list(next(a for a in run.axes if a.name == "heading").candidates)
    choice, solved = solve_folds(crowd_jobs, folds, variants, run.tasks, stream)  # the crowd positions
    t_crowd = time.perf_counter()
    pairs = []
    for _, jobs in planned:
        # a walk whose solve failed adds nothing to the crowd maps (reported per group)
        ids = [j.index for j in jobs]
        for j in jobs:
            stats = fold_stats(choice[j.index], solved, ids, run.cfg.cell_size_m)
            total = WalkStats.total(list(stats.values()))
            cj = dataclasses.replace(j, dir=j.dir / "crowd-map", total=total, held=stats[j.index])
            pairs.append((j, cj))
    results = run_pairs(run, pairs, stream)  # phase 3, both maps of a fold in one worker
    # each walk's own row: its solve with what the other walks taught (its own fold's choice)
    own = {i: solved[c][i] for i, c in choice.items() if i in solved[c]}
    groups_doc = [
        group_doc(p.label, info, jobs, results, own, choice) for p, (info, jobs) in zip(parts, planned)
    ]
    doc = {
        "benchmark": "crowd-map",
        "format": cfg.fmt,
        "dirs": [str(d) for d in cfg.dirs],
        "anchors": cc.anchors,
        "solver": cc.solver,
        "max_sigma_m": cc.max_sigma_m,
        "inputs": "crowd map: per training walk its waypoints every "
        f"{cc.anchors} (anchors) + its site-less STEP stream (no Wi-Fi rows), the heading variant and "
        "fleet priors of the fold's training walks' anchors, scans with posterior sigma <= "
        f"{cc.max_sigma_m} m; truth map: every waypoint",
        "crowd_choices": len(set(choice.values())),
        "params": {
            "cell_size_m": cfg.cell_size_m,
            "min_count": cfg.min_count,
            "firmware_sets": list(run.cfg.param_sets),
            "limit": cfg.limit,
            "jobs": cfg.jobs,
            "scheduler": run.tasks.describe(),
        },
        "stridefixd": {"path": str(run.firmware.path), "version": run.firmware.version()},
        "groups": groups_doc,
    }
    doc["run_s"] = {
        "prepare_plan": t_plan - t_start,
        "crowd_solve": t_crowd - t_plan,
        "folds": time.perf_counter() - t_crowd,
        "total": time.perf_counter() - t_start,
    }
    write_crowd_map_results(cfg.out_json, doc)
    run.stream.close()
    if cfg.quiet:
        stream.close()
    return doc


def run_pairs(
    run: Run, pairs: list[tuple[FoldJob, FoldJob]], stream: TextIO
) -> dict[str, tuple[dict[str, Any], dict[str, Any]]]:
    """Both replays of every fold, in parallel (walk → truth-map result, crowd-map result)."""
    prog = Progress("fold", len(pairs), stream)

    def done(k: int, both: tuple[dict[str, Any], dict[str, Any]]) -> None:
        tr, cr = both
        note = (
            tr["error"]
            or cr["error"]
            or " vs ".join(
                f"{m} {r['fixes'].get('wifi_only', {}).get('mean', math.nan):.1f} m"
                for m, r in (("truth", tr), ("crowd", cr))
            )
        )
        prog.step(f"{pairs[k][0].walk}: wifi_only {note}")

    return {p[0].walk: r for p, r in zip(pairs, run.tasks.map(_pair, pairs, on_result=done))}


def _scores(r: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    return {s: {k: v[k] for k in STATS_KEYS} for s, v in (r.get("fixes") or {}).items()}


def _site(r: Mapping[str, Any]) -> dict[str, Any]:
    f = r.get("fold") or {}
    return {k: f.get(k) for k in ("n_rp", "n_ap", "n_entries", "scans_used")}


def _ratio(crowd: Mapping[str, Any], truth: Mapping[str, Any], scheme: str) -> float:
    c, t = (crowd.get(scheme) or {}).get("mean"), (truth.get(scheme) or {}).get("mean")
    return float(c) / float(t) if c is not None and t and math.isfinite(c) and math.isfinite(t) else math.nan


def _pooled_positions(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Mean position error over every non-anchor waypoint of the walks (per-walk means weighted by n)."""
    out: dict[str, Any] = {}
    for kind in ("graph", "interpolated"):
        st = [r[kind] for r in rows if r.get(kind, {}).get("n")]
        n = sum(s["n"] for s in st)
        out[kind] = {"n": n, "mean_m": sum(s["n"] * s["mean_m"] for s in st) / n if n else math.nan}
    return out


def group_doc(
    label: str,
    info: Mapping[str, Any],
    jobs: Sequence[FoldJob],
    results: Mapping[str, tuple[dict[str, Any], dict[str, Any]]],
    crowd: Mapping[int, Mapping[str, Any]],
    choice: Mapping[int, Choice],
) -> dict[str, Any]:
    """One group: per walk both maps' scores, their ratio and the crowd positions' error; the pooled
    summaries (as ``realbench fusion`` pools them) over the walks scored on both maps."""
    rows, paired_truth, paired_crowd = [], [], []
    for j in jobs:
        tr, cr = results[j.walk]
        c = crowd.get(j.index, {})
        row: dict[str, Any] = {
            "walk": j.walk,
            "error": tr["error"] or cr["error"] or c.get("error"),
            "truth_map": _scores(tr),
            "crowd_map": _scores(cr),
            "sites": {"truth_map": _site(tr), "crowd_map": _site(cr)},
            "crowd_rows": c.get("rows"),
            "crowd_positions": c.get("positions"),
            "crowd_choice": choice_doc(choice[j.index]) if j.index in choice else None,
        }
        row["ratio"] = {s: _ratio(row["crowd_map"], row["truth_map"], s) for s in row["truth_map"]}
        rows.append(row)
        if not (tr["error"] or cr["error"]):
            paired_truth.append(tr)
            paired_crowd.append(cr)
    truth_sum = summarize_group(paired_truth)["schemes"]
    crowd_sum = summarize_group(paired_crowd)["schemes"]
    dropped = sum(int(crowd.get(j.index, {}).get("dropped_uncertain", 0)) for j in jobs)
    n_rows: dict[str, int] = {}
    for j in jobs:
        for k, v in (crowd.get(j.index, {}).get("rows") or {}).items():
            n_rows[k] = n_rows.get(k, 0) + int(v)
    return {
        "label": label,
        "walks": info.get("walks"),
        "ran": info.get("ran"),
        "failed": info.get("failed"),
        "paired": len(paired_truth),
        "crowd_failed": [
            {"walk": crowd[j.index]["walk"], "error": crowd[j.index]["error"]}
            for j in jobs
            if crowd.get(j.index, {}).get("error")
        ],
        "crowd_rows": n_rows,
        "crowd_scans_dropped_uncertain": dropped,
        "crowd_heading_variants": dict(
            collections.Counter(choice[j.index][0] for j in jobs if j.index in choice)
        ),
        "summary": {
            "truth_map": truth_sum,
            "crowd_map": crowd_sum,
            "ratio": {s: _ratio(crowd_sum, truth_sum, s) for s in truth_sum},
            "crowd_positions": _pooled_positions([r["crowd_positions"] or {} for r in rows]),
        },
        "walk_rows": rows,
    }


def format_tables(doc: Mapping[str, Any]) -> str:
    """Per group: one line per walk and the pooled mean — truth map vs crowd map fix error of the
    shown schemes, their ratio, and the crowd positions' error vs the interpolated anchors."""
    lines = []
    for g in doc["groups"]:
        r = g["crowd_rows"]
        lines.append(
            f"crowd-map {g['label']}: {g['paired']} of {g['walks']} walks scored on both maps; crowd "
            f"positions from {r.get('anchors', 0)} anchors ({doc['anchors']}), {r.get('steps', 0)} step "
            f"rows, {r.get('wifi', 0)} Wi-Fi rows"
        )
        variants = ", ".join(f"{v} x{n}" for v, n in (g.get("crowd_heading_variants") or {}).items())
        lines.append(
            f"  learned per fold from the training walks' anchors: heading variant {variants or '-'}; "
            f"{g.get('crowd_scans_dropped_uncertain', 0)} scans left out (sigma > {doc.get('max_sigma_m')} m)"
        )
        head = f"{'walk':<26}" + "".join(f" {s + ' truth':>15} {'crowd':>7} {'ratio':>6}" for s in SHOWN)
        lines.append(head + f" {'pos graph':>10} {'interp':>7}")

        def cells(truth: Mapping[str, Any], crowd: Mapping[str, Any], ratio: Mapping[str, Any]) -> str:
            out = ""
            for s in SHOWN:
                t, c = (truth.get(s) or {}).get("mean", math.nan), (crowd.get(s) or {}).get("mean", math.nan)
                out += f" {t:>15.2f} {c:>7.2f} {ratio.get(s, math.nan):>6.2f}"
            return out

        for w in g["walk_rows"]:
            p = w.get("crowd_positions") or {}
            pg = (p.get("graph") or {}).get("mean_m", math.nan)
            pi = (p.get("interpolated") or {}).get("mean_m", math.nan)
            tail = f"  ({w['error']})" if w["error"] else ""
            lines.append(
                f"{w['walk']:<26}{cells(w['truth_map'], w['crowd_map'], w['ratio'])} {pg:>10.2f} {pi:>7.2f}"
                + tail
            )
        s = g["summary"]
        cp = s["crowd_positions"]
        lines.append(
            f"{'pooled mean':<26}{cells(s['truth_map'], s['crowd_map'], s['ratio'])} "
            f"{cp['graph']['mean_m']:>10.2f} {cp['interpolated']['mean_m']:>7.2f}"
        )
        lines.append("")
    return "\n".join(lines)
