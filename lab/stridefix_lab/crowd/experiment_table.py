"""The results table of ``crowd experiment``: Kannan's rows (thesis mean and std beside ours) and
the stride scale the fitting walks give (Σ truth step / Σ DR step over consecutive truth points)."""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from stridefix_analyzer.crowd.positions import solve_walks
from stridefix_analyzer.crowd.solve import error_stats

from stridefix_lab.crowd.experiment_graph import graph_rows

# (key, label, thesis mean, thesis std, solve options)
ROWS: list[tuple[str, str, float | None, float | None, dict[str, Any]]] = [
    (
        "pdr",
        "PDR only, no weights/filtering",
        10.0143,
        5.097,
        dict(ranges="pdr", pdr_span=0, weights=None, tau=None),
    ),
    ("pdr_w", "PDR only, weights", 3.1467, 2.602, dict(ranges="pdr", pdr_span=0, tau=None)),
    (
        "pdr_wf",
        "PDR only, weights + filtering |i-j|<=2",
        2.1653,
        2.564,
        dict(ranges="pdr", pdr_span=2, tau=None),
    ),
    ("wifi", "Wi-Fi only, no weights/filtering", 7.5489, 4.2453, dict(ranges="wifi", weights=None, tau=None)),
    ("wifi_w", "Wi-Fi only, weights", 4.1095, 3.8607, dict(ranges="wifi", tau=None)),
    ("wifi_wf", "Wi-Fi only, weights + filtering", 3.7228, 3.5579, dict(ranges="wifi")),
    (
        "hybrid",
        "PDR + Wi-Fi (filtered PDR), no weights",
        2.1124,
        2.3614,
        dict(ranges="hybrid", pdr_span=0, weights=None),
    ),
    ("hybrid_w", "PDR + Wi-Fi (filtered PDR), weights", 1.9189, 2.335, dict(ranges="hybrid", pdr_span=0)),
    (
        "both_w",
        "ours: PDR consecutive + filtered Wi-Fi rows, weights",
        None,
        None,
        dict(ranges="both", pdr_span=1),
    ),
]


def stride_scale(walks) -> float:
    """Σ truth chord / Σ DR chord over consecutive truth points of ``walks`` (module docstring)."""
    num = den = 0.0
    for w in walks:
        t = w.scan_t_us if w.dense_truth else w.truth_t_us
        xy, _ = w.place(t)
        dr, _ = w.dead_reckoning(t)
        ok = np.isfinite(xy[:, 0])
        xy, dr = xy[ok], dr[ok]
        num += float(np.sum(np.hypot(*np.diff(xy, axis=0).T)))
        den += float(np.sum(np.hypot(*np.diff(dr, axis=0).T)))
    return num / den if den > 0 else 1.0


def _table_row(
    key: str,
    label: str,
    thesis_mean_m: float | None,
    thesis_std_m: float | None,
    e: dict[str, Any],
    rows: dict[str, int],
    solver: str,
    run_s: float,
) -> dict[str, Any]:
    """One row of the experiment's table: its error statistics next to the thesis's numbers."""
    return {
        "key": key,
        "label": label,
        "thesis_mean_m": thesis_mean_m,
        "thesis_std_m": thesis_std_m,
        **{k: e.get(k) for k in ("mean_m", "std_m", "median_m", "p90_m", "n", "mean_all_m")},
        "rows": rows,
        "solver": solver,
        "run_s": run_s,
    }


def run_table(
    walks, model, anchors: str, solver: str, band: str, scale: float, progress=print, wifi_models=()
) -> tuple[list[dict], dict]:
    """Every row of :data:`ROWS` on ``walks``, then the graph rows (:mod:`.experiment_graph`, with
    each of ``wifi_models``); returns (rows, positions of each thesis row)."""
    out, positions = [], {}
    for key, label, tm, ts, opts in ROWS:
        opts = dict(opts)
        opts.setdefault("weights", (1.0, 2.0))
        opts.setdefault("tau", 0.45)
        opts.setdefault("pdr_span", 1)
        t0 = time.perf_counter()
        xy, points, prob, res = solve_walks(
            walks, model, anchors=anchors, solver=solver, band=band, step_scale=scale, **opts
        )
        e = res["error"]
        out.append(
            _table_row(key, label, tm, ts, e, res["rows"], res["solver"]["solver"], time.perf_counter() - t0)
            | {"problem": res["problem"]}
        )
        positions[key] = (xy, points, prob)
        progress(f"  {label:<55} mean {e.get('mean_m', float('nan')):6.2f} m  ({out[-1]['run_s']:.1f} s)")
    # reference: the initial guess alone (anchors interpolated linearly in time, no range rows)
    xy, points, prob = positions[ROWS[0][0]]
    e = error_stats(prob.x0, points, prob)
    rows = {"anchors": int(len(prob.anchor_index)), "pdr": 0, "wifi": 0}
    out.append(
        _table_row("anchors_interp", "reference: anchors only, linear in time", None, None, e, rows, "-", 0.0)
        | {"problem": {}}
    )
    out += graph_rows(walks, anchors, solver, band, wifi_models, progress)
    return out, positions


def format_table(rows: list[dict]) -> str:
    head = (
        f"{'method':<64}{'mean m':>8}{'std m':>8}{'p90 m':>8}{'n':>6}{'rows':>9}"
        f"{'thesis mean':>13}{'thesis std':>11}"
    )
    lines = [head]
    for r in rows:

        def f(v, w=8):
            return f"{v:>{w}.2f}" if v is not None else f"{'-':>{w}}"

        nrows = r["rows"]["pdr"] + r["rows"]["wifi"]
        label = r["label"] if nrows or r["key"] == "anchors_interp" else r["label"] + " [0 rows: = anchors]"
        lines.append(
            f"{label:<64}{f(r['mean_m'])}{f(r['std_m'])}{f(r['p90_m'])}"
            f"{r['n'] or 0:>6}{nrows:>9}{f(r['thesis_mean_m'], 13)}{f(r['thesis_std_m'], 11)}"
        )
    return "\n".join(lines)
