"""The crowd graph solve at fleet scale: groups of walks as independent tasks (serial or on Dask).

Without Wi-Fi rows the graph of :mod:`.graph` is block-diagonal per walk (steps, heading and scale rows
tie only the points of one walk; anchors are unary), so its minimiser is the union of the minimisers
of any partition of the walks into groups. ``solve_walks_grouped`` partitions the walks (``per="floor"``:
the walks of a floor, what Wi-Fi rows would join, so the same split stays valid with them; ``"chunk:K"``:
K consecutive walks; ``"all"``: one problem) and solves each group with
:func:`.graph_run.solve_walks_graph` as a task of :func:`stridefix_analyzer.parallel.run_tasks`. Each group's problem is
solved by Ceres when ``stridefix_native.solve_graph`` is importable, else by the scipy twin (sparse
analytic Jacobian, LSMR); the info names which ran.

Errors (as :func:`.solve.error_stats`): ‖p̂ − truth‖ at the truth points that were not anchors.
"""

from __future__ import annotations

import re
import time
from typing import Any

import numpy as np
from stridefix_analyzer.crowd.graph import GraphSettings
from stridefix_analyzer.crowd.graph_run import solve_walks_graph
from stridefix_analyzer.crowd.walks import DEFAULT_BAND, CrowdInputError, Walk
from stridefix_analyzer.parallel import run_tasks


def walk_groups(walks: list[Walk], per: str = "floor") -> list[list[int]]:
    """Walk indices per group (module docstring); a walk's floor is its first truth floor."""
    if per == "all":
        return [list(range(len(walks)))]
    if per == "floor":
        floor = np.array([int(w.truth_floor[0]) if len(w.truth_floor) else -9999 for w in walks])
        return [np.flatnonzero(floor == f).tolist() for f in np.unique(floor)]
    m = re.fullmatch(r"chunk:(\d+)", per)
    if m and int(m.group(1)) > 0:
        k = int(m.group(1))
        return [list(range(i, min(len(walks), i + k))) for i in range(0, len(walks), k)]
    raise CrowdInputError(f"walk groups {per!r}: expected floor, all or chunk:K")


def _solve_group(task: tuple[list[Walk], dict[str, Any]], shared: Any = None) -> dict[str, Any]:
    """One group's solve → positions, which points are truth / anchors, their truth, and the info."""
    del shared
    walks, kw = task
    t0 = time.perf_counter()
    run = solve_walks_graph(walks, **kw)
    anchored = np.zeros(run.problem.n_points, bool)
    anchored[run.problem.anchor_idx] = True
    return {
        "xy_m": run.xy_m,
        "truth_xy_m": run.points.truth_xy_m,
        "is_truth": run.points.is_truth,
        "is_scan": run.points.is_scan,
        "anchored": anchored,
        "rows": run.info["rows"],
        "solver": run.info["solver"],
        "task_s": time.perf_counter() - t0,
    }


def _errors(e: np.ndarray) -> dict[str, Any]:
    if e.size == 0:
        return {"n": 0}
    return {
        "n": int(e.size),
        "mean_m": float(e.mean()),
        "median_m": float(np.median(e)),
        "p90_m": float(np.percentile(e, 90)),
        "max_m": float(e.max()),
    }


def solve_walks_grouped(
    walks: list[Walk],
    per: str = "floor",
    *,
    scheduler: str | None = None,
    workers: int = 2,
    anchors: str = "every:4",
    settings: GraphSettings | None = None,
    band: str = DEFAULT_BAND,
    solver: str = "auto",
    client: Any = None,
) -> dict[str, Any]:
    """Solve the walks' graph (no Wi-Fi rows) group by group; returns positions and a summary."""
    t0 = time.perf_counter()
    groups = walk_groups(walks, per)
    kw = {"anchors": anchors, "settings": settings or GraphSettings(), "band": band, "solver": solver}
    tasks = [([walks[i] for i in g], kw) for g in groups]
    parts = run_tasks(_solve_group, tasks, scheduler, workers, client=client)
    cat = np.concatenate
    xy, truth = cat([p["xy_m"] for p in parts]), cat([p["truth_xy_m"] for p in parts])
    is_truth, anchored = cat([p["is_truth"] for p in parts]), cat([p["anchored"] for p in parts])
    is_scan = cat([p["is_scan"] for p in parts])
    err = np.hypot(*(xy - truth).T)
    rows: dict[str, int] = {}
    for p in parts:
        for k, v in p["rows"].items():
            rows[k] = rows.get(k, 0) + int(v)
    solvers = sorted({str(p["solver"].get("solver")) for p in parts})
    return {
        "groups": per,
        "n_groups": len(groups),
        "walks": len(walks),
        "points": int(len(xy)),
        "scan_points": int(is_scan.sum()),
        "truth_points": int(is_truth.sum()),
        "rows": rows,
        "solver": solvers,
        "converged": all(bool(p["solver"].get("converged")) for p in parts),
        "error_non_anchor_truth": _errors(err[is_truth & ~anchored]),
        "error_scans": _errors(err[is_scan & np.isfinite(err)]),
        "task_s": [float(p["task_s"]) for p in parts],
        "solve_s": time.perf_counter() - t0,
        "xy_m": xy,
    }
