"""Crowd walks → solved positions with the graph (:mod:`.graph`, :mod:`.graph_solve`): the one entry
point that ``crowd solve``, ``crowd radiomap``, the experiment and realbench's crowd-built map call.

Anchors are every K-th truth point of each walk (what a crowd walk carries: a beacon, a landmark, a
surveyed waypoint); the truth of the other points is never read here, only by :func:`.solve.
error_stats` afterwards. What the graph cannot take from physics it learns from the anchors too:
the fleet's stride scale and heading bias (:func:`.graph.fleet_priors`) and how fast the heading bias
wanders (:func:`choose_heading_sigma`, cross-validation on the anchors: every other anchor of each
walk is held out, the walk solved from the rest, the held-out anchors scored). A unit in the field
and a crowd map both have anchors and nothing else.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from stridefix_analyzer.crowd.graph import (
    DEFAULT_SETTINGS,
    FleetPriors,
    GraphProblem,
    GraphSettings,
    anchor_mask,
    build_graph,
    fleet_priors,
)
from stridefix_analyzer.crowd.graph_solve import solve_graph
from stridefix_analyzer.crowd.solve import Points, make_points, parse_anchors
from stridefix_analyzer.crowd.walks import DEFAULT_BAND, ScanSet, Walk, pool_scans

#: Heading-bias random walk [rad/√s] tried by the anchor cross-validation: from a phone held still
#: (gyro drift only, ~0.02) to one turned in the hand every few seconds (0.4).
HEADING_SIGMA_GRID = (0.02, 0.05, 0.1, 0.2, 0.4)


@dataclasses.dataclass
class GraphRun:
    """One solve: positions (n, 2) of ``points``, the problem, and what was used."""

    xy_m: np.ndarray
    points: Points
    scans: ScanSet
    problem: GraphProblem
    info: dict[str, Any]

    @property
    def anchor_index(self) -> np.ndarray:  # what .solve.error_stats reads
        return self.problem.anchor_idx

    @property
    def n(self) -> int:
        return self.problem.n_points


def choose_heading_sigma(
    points: Points,
    n_walks: int,
    is_anchor: np.ndarray,
    settings: GraphSettings,
    priors: FleetPriors,
    solver: str = "auto",
    grid=HEADING_SIGMA_GRID,
) -> tuple[float, list[dict[str, Any]]]:
    """σ_θ of ``grid`` with the lowest mean error at held-out anchors (module docstring); the
    settings' own value when no walk has a second anchor to hold out."""
    keep = np.zeros_like(is_anchor)
    held = np.zeros_like(is_anchor)
    for k in range(n_walks):
        ak = np.flatnonzero((points.walk == k) & is_anchor)
        keep[ak[::2]] = True
        held[ak[1::2]] = True
    if not held.any():
        return settings.heading_sigma_rad_per_sqrt_s, []
    priors = fleet_priors(points, keep, n_walks)  # the held-out anchors teach nothing
    rows = []
    for sig in grid:
        s = dataclasses.replace(settings, heading_sigma_rad_per_sqrt_s=float(sig))
        g = build_graph(points, n_walks, anchors=keep, settings=s, priors=priors)
        xy = solve_graph(g, solver).xy_m
        e = np.hypot(*(xy[held] - points.truth_xy_m[held]).T)
        rows.append(
            {
                "heading_sigma_rad_per_sqrt_s": float(sig),
                "heldout_anchor_mean_m": float(e.mean()),
                "n": int(e.size),
            }
        )
    best = min(rows, key=lambda r: r["heldout_anchor_mean_m"])
    return best["heading_sigma_rad_per_sqrt_s"], rows


def solve_walks_graph(
    walks: list[Walk],
    *,
    anchors: str = "every:4",
    settings: GraphSettings = DEFAULT_SETTINGS,
    learn_heading_sigma: bool = True,
    wifi_model: Any = None,
    band: str = DEFAULT_BAND,
    solver: str = "auto",
) -> GraphRun:
    """Build the graph of ``walks`` and solve it. ``wifi_model``: a fitted pair model giving
    loop-closure rows (:mod:`.graph_wifi`), or None for none. ``learn_heading_sigma``: choose σ_θ by
    anchor cross-validation (else the settings' value)."""
    t0 = time.perf_counter()
    scans = pool_scans(walks, band)
    points = make_points(walks, scans)
    is_anchor = anchor_mask(points, len(walks), parse_anchors(anchors))
    priors = fleet_priors(points, is_anchor, len(walks))
    cv: list[dict[str, Any]] = []
    if learn_heading_sigma:
        sig, cv = choose_heading_sigma(points, len(walks), is_anchor, settings, priors, solver)
        settings = dataclasses.replace(settings, heading_sigma_rad_per_sqrt_s=sig)
    g = build_graph(points, len(walks), anchors=is_anchor, settings=settings, priors=priors)
    if wifi_model is not None:
        from stridefix_analyzer.crowd.graph_wifi import add_wifi_rows  # noqa: PLC0415

        g = add_wifi_rows(g, points, scans, wifi_model, settings)
    build_s = time.perf_counter() - t0
    sol = solve_graph(g, solver)
    info = {
        "anchors": anchors,
        "rows": g.rows(),
        "settings": dataclasses.asdict(settings),
        "priors": dataclasses.asdict(priors),
        "heading_sigma_cv": cv,
        "wifi_model": getattr(wifi_model, "name", None) if wifi_model is not None else None,
        "solver": sol.info,
        "build_s": build_s,
        "scale": [float(s) for s in sol.scale],
    }
    return GraphRun(sol.xy_m, points, scans, g, info)
