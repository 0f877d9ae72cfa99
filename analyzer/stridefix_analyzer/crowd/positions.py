"""``stridefix crowd solve``: 2-D positions of the points of a set of walks from anchors and ranges.

Anchors are a subset of the truth points; range rows come from PDR and/or the Wi-Fi model
(:mod:`.solve` builds and solves the problem) → ``solve.json``, ``positions.csv``, ``solve.png``;
error at the non-anchor truth points.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from typing import Any

import numpy as np

from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd.fit import read_model
from stridefix_analyzer.crowd.solve import build_problem, error_stats, make_points, solve
from stridefix_analyzer.crowd.walks import DEFAULT_BAND, Walk, load_walks, pool_scans


def solve_walks(
    walks: list[Walk],
    model: cm.DistanceModel | None,
    *,
    ranges: str,
    anchors: str,
    pdr_span: int = 1,
    pdr_metric: str = "chord",
    weights=(1.0, 2.0),
    tau: float | None = cm.DEFAULT_TAU,
    band: str = DEFAULT_BAND,
    solver: str = "auto",
    step_scale: float = 1.0,
):
    """Build and solve one problem; returns (positions (n, 2), points, problem, result dict)."""
    t0 = time.perf_counter()
    if step_scale != 1.0:
        for w in walks:
            w.step_length_m = w.step_length_m * step_scale
    try:
        scans = pool_scans(walks, band)
        points = make_points(walks, scans)
        prob = build_problem(
            walks,
            scans,
            points,
            model=model,
            ranges=ranges,
            anchors=anchors,
            pdr_span=pdr_span,
            pdr_metric=pdr_metric,
            weights=weights,
            tau=tau,
        )
    finally:
        if step_scale != 1.0:
            for w in walks:
                w.step_length_m = w.step_length_m / step_scale
    build_s = time.perf_counter() - t0
    xy, sinfo = solve(prob, solver)
    res = {
        "problem": prob.info,
        "solver": sinfo,
        "error": error_stats(xy, points, prob),
        "build_s": build_s,
        "rows": {
            "anchors": int(len(prob.anchor_index)),
            "pdr": int(np.sum(prob.row_kind == 0)),
            "wifi": int(np.sum(prob.row_kind == 1)),
        },
    }
    return xy, points, prob, res


def solve_graph_args(args: argparse.Namespace, walks: list[Walk]) -> tuple[Any, Any, Any, dict[str, Any]]:
    """The crowd graph (:mod:`.graph_run`) with the options of ``crowd solve``: steps + anchors, and
    Wi-Fi loop closures when ``--model`` names a pair model (``crowd models`` / ``crowd fit``)."""
    from stridefix_analyzer.crowd.graph_run import solve_walks_graph  # noqa: PLC0415 - import cycle

    model = None
    if args.model:
        from stridefix_analyzer.crowd.models import read_pair_model  # noqa: PLC0415

        model = read_pair_model(args.model)
    run = solve_walks_graph(walks, anchors=args.anchors, wifi_model=model, band=args.band, solver=args.solver)
    r = run.info["rows"]
    res = {
        "problem": {"points": run.n, "ranges": "graph", "anchors": args.anchors} | run.info,
        "solver": run.info["solver"],
        "error": error_stats(run.xy_m, run.points, run),
        "build_s": run.info["build_s"],
        "rows": {"anchors": r["anchors"], "pdr": r["steps"], "wifi": r["wifi"]},
    }
    return run.xy_m, run.points, run, res


def solve_args(args: argparse.Namespace, walks: list[Walk]) -> tuple[Any, Any, Any, dict[str, Any]]:
    """:func:`solve_walks` with the options of ``crowd solve`` / ``crowd radiomap``."""
    if args.ranges == "graph":
        return solve_graph_args(args, walks)
    return solve_walks(
        walks,
        read_model(args.model) if args.model else None,
        ranges=args.ranges,
        anchors=args.anchors,
        pdr_span=args.pdr_span,
        pdr_metric=args.pdr_metric,
        weights=None if args.no_weights else (args.weight_m, args.weight_c),
        tau=None if args.no_filter else args.tau,
        band=args.band,
        solver=args.solver,
        step_scale=args.step_scale,
    )


def run_solve(args: argparse.Namespace) -> dict[str, Any]:
    walks = load_walks(args.logs)
    xy, points, prob, res = solve_args(args, walks)
    os.makedirs(args.out, exist_ok=True)
    res["inputs"] = [w.name for w in walks]
    with open(os.path.join(args.out, "solve.json"), "w") as f:
        json.dump(res, f, indent=2, default=float)
        f.write("\n")
    write_positions(os.path.join(args.out, "positions.csv"), xy, points, prob)
    from stridefix_analyzer.crowd.plots import plot_solution

    e = res["error"]
    plot_solution(
        xy,
        points.truth_xy_m,
        points.is_truth,
        prob.anchor_index,
        os.path.join(args.out, "solve.png"),
        f"{args.ranges}: mean error {e.get('mean_m', math.nan):.2f} m, std {e.get('std_m', math.nan):.2f} m",
    )
    print(format_solve(res))
    print(f"wrote {args.out}/solve.json, positions.csv, solve.png")
    return res


def format_solve(res: dict) -> str:
    p, s, e, r = res["problem"], res["solver"], res["error"], res["rows"]
    if p["ranges"] == "graph":
        g, pr = p["rows"], p["priors"]
        lines = [
            f"problem  graph of {p['points']} points: {g['anchors']} anchors ({p['anchors']}), {g['steps']} "
            f"step rows, {g['heading']} heading rows, {g['heading_prior']} heading priors, {g['scale']} "
            f"stride scales, {g['wifi']} Wi-Fi rows ({p['wifi_model'] or 'no pair model'}); learned from the "
            f"anchors: fleet scale {pr['scale']:.2f} ± {pr['scale_sigma']:.2f}, heading bias "
            f"{math.degrees(pr['heading_rad']):.0f}° ± {math.degrees(pr['heading_sigma_rad']):.0f}° "
            f"({pr['walks_used']} walks), σ_θ {p['settings']['heading_sigma_rad_per_sqrt_s']:g} rad/√s",
            f"solver   {s['solver']} ({s['solve_s']:.2f} s)" + (f"; {s['note']}" if "note" in s else ""),
        ]
        return "\n".join(lines + _error_line(e))
    lines = [
        f"problem  {p['points']} points, {r['anchors']} anchors ({p['anchors']}), "
        f"{r['pdr']} PDR rows (span {p['pdr_span']}, {p['pdr_metric']}), {r['wifi']} Wi-Fi rows; "
        f"ranges {p['ranges']}, weights {p['weights']}, tau {p['tau']}"
        + (
            f", Wi-Fi threshold {p['wifi_threshold_m']:.2f} m"
            if p.get("wifi_threshold_m") is not None and np.isfinite(p.get("wifi_threshold_m", math.nan))
            else ""
        ),
        f"solver   {s['solver']} ({s['solve_s']:.2f} s)" + (f"; {s['note']}" if "note" in s else ""),
    ]
    return "\n".join(lines + _error_line(e))


def _error_line(e: dict) -> list[str]:
    if not e.get("n"):
        return []
    return [
        f"error    at {e['n']} non-anchor truth points: mean {e['mean_m']:.2f} m, std "
        f"{e['std_m']:.2f} m, median {e['median_m']:.2f} m, p90 {e['p90_m']:.2f} m, "
        f"RMSE {e['rmse_m']:.2f} m (incl. anchors, as the thesis: mean "
        f"{e['mean_all_m']:.2f} m)"
    ]


def write_positions(path: str, xy, points, prob) -> None:
    is_anchor = np.zeros(prob.n, bool)
    is_anchor[prob.anchor_index] = True
    with open(path, "w") as f:
        f.write("walk,t_us,is_scan,is_truth,is_anchor,x_m,y_m,x_gt_m,y_gt_m\n")
        for k in range(prob.n):
            f.write(
                f"{points.walk[k]},{points.t_us[k]},{int(points.is_scan[k])},"
                f"{int(points.is_truth[k])},{int(is_anchor[k])},{xy[k, 0]:.3f},{xy[k, 1]:.3f},"
                f"{points.truth_xy_m[k, 0]:.3f},{points.truth_xy_m[k, 1]:.3f}\n"
            )
