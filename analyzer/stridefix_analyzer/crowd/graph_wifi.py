"""Wi-Fi loop closures for the crowd graph: range rows between points of different walks whose
fingerprints a fitted pair model says are near each other.

A fitted pair model (:mod:`.models`: ``predict(Ra, Rb) -> (distance_m, sigma_m)``) gives every pair
of fingerprints a distance and its spread. Only near pairs carry information (far fingerprints all
look alike, Kannan 2024 §4's reliability filter), so a point gets at most ``wifi_per_point`` rows, to
its most similar fingerprints in *other* walks on the same floor, each with predicted distance ≤
``wifi_max_range_m``. Candidates are searched only among points whose initial positions (anchors
interpolated in time) lie within ``search_radius_m`` of each other (a k-d tree,
``scipy.spatial.cKDTree``): the cost is O(n·neighbours), not O(n²), so a fleet of walks stays sparse.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.spatial import cKDTree

from stridefix_analyzer.crowd.graph import GraphProblem, GraphSettings
from stridefix_analyzer.crowd.solve import Points
from stridefix_analyzer.crowd.walks import ScanSet

#: Candidate pairs: initial positions within this [m]. Anchors every 4th waypoint keep a walk's
#: interpolated guess within ~10 m of where it is; the search allows three times that.
SEARCH_RADIUS_M = 30.0
BLOCK = 256


def wifi_rows(points: Points, scans: ScanSet, model, settings: GraphSettings, init_xy_m: np.ndarray):
    """(i, j, range_m, sigma_m) of the loop closures (module docstring)."""
    idx = np.flatnonzero(points.fp >= 0)
    empty = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros(0))
    if len(idx) < 2 or settings.wifi_per_point <= 0:
        return empty
    R = scans.R[points.fp[idx]]
    tree = cKDTree(init_xy_m[idx])
    walk, floor = points.walk[idx], points.floor[idx]
    out_i, out_j, out_d, out_s = [], [], [], []
    for b0 in range(0, len(idx), BLOCK):
        rows = np.arange(b0, min(len(idx), b0 + BLOCK))
        near = tree.query_ball_point(init_xy_m[idx[rows]], SEARCH_RADIUS_M)
        cols = np.unique(np.concatenate([np.asarray(n, np.int64) for n in near]))
        if len(cols) == 0:
            continue
        d, s = model.predict(R[rows], R[cols])
        ok = np.zeros(d.shape, bool)
        for r, nb in enumerate(near):
            ok[r, np.searchsorted(cols, nb)] = True
        ok &= walk[rows][:, None] != walk[cols][None, :]
        ok &= floor[rows][:, None] == floor[cols][None, :]
        with np.errstate(invalid="ignore"):
            ok &= np.isfinite(d) & np.isfinite(s) & (s > 0) & (d <= settings.wifi_max_range_m)
        dd = np.where(ok, d, np.inf)
        k = min(settings.wifi_per_point, dd.shape[1])
        best = np.argpartition(dd, k - 1, axis=1)[:, :k]
        rr = np.repeat(np.arange(len(rows)), k)
        cc = best.ravel()
        keep = np.isfinite(dd[rr, cc])
        rr, cc = rr[keep], cc[keep]
        out_i.append(idx[rows[rr]])
        out_j.append(idx[cols[cc]])
        out_d.append(d[rr, cc])
        out_s.append(s[rr, cc])
    if not out_i:
        return empty
    i, j, d, s = (np.concatenate(v) for v in (out_i, out_j, out_d, out_s))
    # a pair found from both ends is one row
    a, b = np.minimum(i, j), np.maximum(i, j)
    _, first = np.unique(a * (len(points.t_us) + 1) + b, return_index=True)
    return a[first], b[first], d[first], s[first]


def add_wifi_rows(
    g: GraphProblem, points: Points, scans: ScanSet, model, settings: GraphSettings
) -> GraphProblem:
    """``g`` with the loop closures of :func:`wifi_rows` as its range rows."""
    i, j, d, s = wifi_rows(points, scans, model, settings, g.init_xy_m)
    return dataclasses.replace(
        g,
        pair_i=i.astype(np.int64),
        pair_j=j.astype(np.int64),
        range_m=np.asarray(d, float),
        range_sigma_m=np.asarray(s, float),
    )
