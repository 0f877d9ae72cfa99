"""Crowd walks → solved positions with the graph (:mod:`.graph`, :mod:`.graph_solve`): the one entry
point that ``crowd solve``, ``crowd radiomap``, the experiment and realbench's crowd-built map call.

Anchors are every K-th truth point of each walk (what a crowd walk carries: a beacon, a landmark, a
surveyed waypoint); the truth of the other points is never read here, only by :func:`.solve.
error_stats` afterwards. What the graph cannot take from physics it learns from the anchors too:
the fleet's stride scale and heading bias (:func:`.graph.fleet_priors`) how fast the heading bias
wanders (:func:`choose_heading_sigma`) and whether a pair model's Wi-Fi loop closures help, both by
cross-validation on the anchors: every other anchor of each walk is held out, the walks solved
from the rest, the held-out anchors scored. A unit in the field
and a crowd map both have anchors and nothing else.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
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
    walk_similarity,
)
from stridefix_analyzer.crowd.graph_solve import GraphSolution, solve_graph
from stridefix_analyzer.crowd.graph_wifi import add_wifi_rows
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
    solution: GraphSolution  # xy_m with the headings and scales (what position_sigma_m linearises at)

    @property
    def anchor_index(self) -> np.ndarray:  # what .solve.error_stats reads
        return self.problem.anchor_idx

    @property
    def n(self) -> int:
        return self.problem.n_points


def anchor_similarities(walks: list[Walk], anchors: str) -> list[tuple[float, float] | None]:
    """Each walk's :func:`.graph.walk_similarity` on its own anchors (every K-th truth point)."""
    every = parse_anchors(anchors)
    out = []
    for w in walks:
        points = make_points([w], pool_scans([w], "all"))
        out.append(walk_similarity(points, anchor_mask(points, 1, every), 0))
    return out


def split_anchors(points: Points, n_walks: int, is_anchor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(kept, held out): every other anchor of each walk, its first kept."""
    keep = np.zeros_like(is_anchor)
    held = np.zeros_like(is_anchor)
    for k in range(n_walks):
        ak = np.flatnonzero((points.walk == k) & is_anchor)
        keep[ak[::2]] = True
        held[ak[1::2]] = True
    return keep, held


def anchor_cv_error(
    points: Points,
    n_walks: int,
    is_anchor: np.ndarray,
    make: Callable[..., GraphProblem],
    solver: str,
    priors: FleetPriors | None = None,
) -> dict[str, Any]:
    """Mean error at the held-out anchors of the graph ``make(keep, priors)`` built on the kept ones
    (fleet priors re-learned from the kept anchors, so the held-out ones teach nothing; or the given
    ``priors``, learned from a fleet of other walks)."""
    keep, held = split_anchors(points, n_walks, is_anchor)
    if not held.any():
        return {"heldout_anchor_mean_m": math.nan, "n": 0}
    pri = fleet_priors(points, keep, n_walks) if priors is None else priors
    xy = solve_graph(make(keep, pri), solver).xy_m
    e = np.hypot(*(xy[held] - points.truth_xy_m[held]).T)
    return {"heldout_anchor_mean_m": float(e.mean()), "n": int(e.size)}


def choose_heading_sigma(
    points: Points,
    n_walks: int,
    is_anchor: np.ndarray,
    settings: GraphSettings,
    solver: str = "auto",
    grid=HEADING_SIGMA_GRID,
    priors: FleetPriors | None = None,
) -> tuple[float, list[dict[str, Any]]]:
    """σ_θ of ``grid`` with the lowest mean error at held-out anchors (module docstring); the
    settings' own value when no walk has a second anchor to hold out."""
    rows = []
    for sig in grid:
        s = dataclasses.replace(settings, heading_sigma_rad_per_sqrt_s=float(sig))

        def make(keep, priors, s=s):
            return build_graph(points, n_walks, anchors=keep, settings=s, priors=priors)

        rows.append(
            {"heading_sigma_rad_per_sqrt_s": float(sig)}
            | anchor_cv_error(points, n_walks, is_anchor, make, solver, priors)
        )
    if not rows[0]["n"]:
        return settings.heading_sigma_rad_per_sqrt_s, []
    best = min(rows, key=lambda r: r["heldout_anchor_mean_m"])
    return best["heading_sigma_rad_per_sqrt_s"], rows


def solve_walks_graph(
    walks: list[Walk],
    *,
    anchors: str = "every:4",
    settings: GraphSettings = DEFAULT_SETTINGS,
    learn_heading_sigma: bool = True,
    wifi_model: Any = None,
    wifi: str = "auto",
    band: str = DEFAULT_BAND,
    solver: str = "auto",
    priors: FleetPriors | None = None,
) -> GraphRun:
    """Build the graph of ``walks`` and solve it. ``wifi_model``: a fitted pair model giving
    loop-closure rows (:mod:`.graph_wifi`), or None for none; ``wifi``: ``auto`` = keep its rows only
    when they lower the held-out anchor error, ``on`` = always. ``learn_heading_sigma``: choose σ_θ
    by anchor cross-validation (else the settings' value). ``priors``: the stride scale and heading
    bias of a fleet of walks (e.g. a crowd map's other walks, :func:`.graph.priors_from`); default:
    learned from ``walks``' own anchors (:func:`.graph.fleet_priors`)."""
    t0 = time.perf_counter()
    scans = pool_scans(walks, band)
    points = make_points(walks, scans)
    is_anchor = anchor_mask(points, len(walks), parse_anchors(anchors))
    given = priors
    priors = fleet_priors(points, is_anchor, len(walks)) if given is None else given
    n_walks = len(walks)
    cv: list[dict[str, Any]] = []
    if learn_heading_sigma:
        sig, cv = choose_heading_sigma(points, n_walks, is_anchor, settings, solver, priors=given)
        settings = dataclasses.replace(settings, heading_sigma_rad_per_sqrt_s=sig)
    g = build_graph(points, n_walks, anchors=is_anchor, settings=settings, priors=priors)
    wifi_cv: dict[str, Any] = {}
    if wifi_model is not None:

        def make(keep, pri, with_wifi):
            gk = build_graph(points, n_walks, anchors=keep, settings=settings, priors=pri)
            return add_wifi_rows(gk, points, scans, wifi_model, settings) if with_wifi else gk

        if wifi == "auto":
            for label, flag in (("without", False), ("with", True)):
                wifi_cv[label] = anchor_cv_error(
                    points, n_walks, is_anchor, lambda k, p, f=flag: make(k, p, f), solver, given
                )
            e_with, e_without = (wifi_cv[k]["heldout_anchor_mean_m"] for k in ("with", "without"))
            wifi_cv["used"] = bool(e_with < e_without)  # NaN (nothing held out) compares False
        else:
            wifi_cv["used"] = wifi == "on"
        if wifi_cv["used"]:
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
        "wifi_cv": wifi_cv,
        "solver": sol.info,
        "build_s": build_s,
        "scale": [float(s) for s in sol.scale],
    }
    return GraphRun(sol.xy_m, points, scans, g, info, sol)
