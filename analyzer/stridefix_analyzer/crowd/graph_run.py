"""Crowd walks → solved positions with the graph (:mod:`.graph`, :mod:`.graph_solve`): the one entry
point that ``crowd solve --ranges graph``, ``crowd radiomap``, the experiment and realbench's crowd-built
map all call.

Anchors are every K-th truth point of each walk (what a crowd walk carries: a beacon, a landmark, a
surveyed waypoint); the truth of the other points is never read here, only by :func:`.solve.
error_stats` afterwards.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from stridefix_analyzer.crowd.graph import GraphProblem, GraphSettings, build_graph
from stridefix_analyzer.crowd.graph_solve import solve_graph
from stridefix_analyzer.crowd.solve import Points, make_points
from stridefix_analyzer.crowd.walks import DEFAULT_BAND, ScanSet, Walk, pool_scans


@dataclasses.dataclass
class GraphRun:
    """One solve: positions (n, 2) of ``points``, the problem, and what was used."""

    xy_m: np.ndarray
    points: Points
    scans: ScanSet
    problem: GraphProblem
    info: dict[str, Any]


def solve_walks_graph(
    walks: list[Walk],
    *,
    anchors: str | np.ndarray = "every:4",
    settings: GraphSettings = GraphSettings(),
    scale_prior: float = 1.0,
    wifi_model: Any = None,
    band: str = DEFAULT_BAND,
    solver: str = "auto",
) -> GraphRun:
    """Build the graph of ``walks`` and solve it. ``wifi_model``: a fitted pair model with loop-closure
    rows (see :mod:`.graph_wifi`), or None for no Wi-Fi rows."""
    t0 = time.perf_counter()
    scans = pool_scans(walks, band)
    points = make_points(walks, scans)
    wifi = None
    if wifi_model is not None:
        from stridefix_analyzer.crowd.graph_wifi import wifi_rows  # noqa: PLC0415 - optional rows

        wifi = wifi_rows(points, scans, wifi_model, settings)
    g = build_graph(
        points, len(walks), anchors=anchors, settings=settings, scale_prior=scale_prior, wifi_rows=wifi
    )
    build_s = time.perf_counter() - t0
    sol = solve_graph(g, solver)
    info = {
        "rows": g.rows(),
        "settings": dataclasses.asdict(settings),
        "scale_prior": scale_prior,
        "wifi_model": getattr(wifi_model, "name", None) if wifi_model is not None else None,
        "solver": sol.info,
        "build_s": build_s,
        "scale": [float(s) for s in sol.scale],
    }
    return GraphRun(sol.xy_m, points, scans, g, info)
