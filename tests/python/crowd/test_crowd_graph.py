"""The crowd graph (crowd/graph*.py): exact recovery, the Jacobian, fleet priors, loop closures."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from stridefix_analyzer.crowd import graph_solve as gs
from stridefix_analyzer.crowd.graph import GraphSettings, build_graph, fleet_priors
from stridefix_analyzer.crowd.graph_run import choose_heading_sigma
from stridefix_analyzer.crowd.graph_wifi import wifi_rows
from stridefix_analyzer.crowd.solve import Points


def _walks(rng, n_walks=4, n=60, scale=1.1, bias_rad=0.4, drift_rad_per_s=0.0, retrace=None):
    """Curved walks (1 s apart); DR = the truth rotated by −bias(t) and divided by the scale.

    ``bias_rad``: one bias for every walk, or one per walk. ``retrace=(k, m)``: walk k walks walk m's
    path 1 m to its side (two walkers of one corridor: the pair a loop closure joins)."""
    parts, paths = [], []
    for k in range(n_walks):
        heading = np.cumsum(rng.normal(0, 0.25, n)) + k
        start = rng.uniform(-20, 20, 2)
        if retrace is not None and k == retrace[0]:
            heading, start = paths[retrace[1]][0], paths[retrace[1]][1] + np.array([0.0, 1.0])
        paths.append((heading, start))
        step = np.column_stack([np.cos(heading), np.sin(heading)]) * 1.3
        xy = np.cumsum(step, axis=0) + start
        b = np.broadcast_to(bias_rad, n_walks)[k] + drift_rad_per_s * np.arange(n)
        c, s = np.cos(-b), np.sin(-b)
        dstep = np.column_stack([c * step[:, 0] - s * step[:, 1], s * step[:, 0] + c * step[:, 1]]) / scale
        dr = np.cumsum(dstep, axis=0)
        parts.append((np.full(n, k), np.arange(n) * 1_000_000 + k, xy, dr))
    walk, t, xy, dr = (np.concatenate(v) for v in zip(*parts))
    m = len(walk)
    return Points(
        walk=walk,
        t_us=t,
        is_scan=np.ones(m, bool),
        fp=np.arange(m),
        truth_xy_m=xy,
        floor=np.zeros(m, np.int64),
        is_truth=np.ones(m, bool),
        dr_xy_m=dr,
        dr_path_m=np.zeros(m),
    )


def _error(xy, pts, g):
    free = np.ones(len(xy), bool)
    free[g.anchor_idx] = False
    return float(np.mean(np.hypot(*(xy[free] - pts.truth_xy_m[free]).T)))


def test_exact_dead_reckoning_is_recovered_with_scale_and_heading():
    """GIVEN exact DR (scale 1.1, bias 0.4 rad) and anchors every 8th point
    THEN positions within 2 cm, scale and heading recovered; anchor interpolation is 10× worse."""
    pts = _walks(np.random.default_rng(1))
    g = build_graph(pts, 4, anchors="every:8")
    sol = gs.solve_graph_scipy(g)
    assert _error(sol.xy_m, pts, g) < 0.02
    assert np.allclose(sol.scale, 1.1, atol=0.01)
    assert np.allclose(sol.heading_rad, 0.4, atol=0.01)
    assert _error(g.init_xy_m, pts, g) > 10 * _error(sol.xy_m, pts, g)


def test_fleet_priors_from_anchors_only():
    pts = _walks(np.random.default_rng(2), n_walks=6)
    is_anchor = np.zeros(len(pts.t_us), bool)
    is_anchor[::8] = True
    pts_bad = dataclasses.replace(pts, truth_xy_m=np.where(is_anchor[:, None], pts.truth_xy_m, 1e6))
    fp = fleet_priors(pts_bad, is_anchor, 6)  # non-anchor truth must not be read
    assert fp.walks_used == 6
    assert fp.scale == pytest.approx(1.1, abs=0.01)
    assert fp.heading_rad == pytest.approx(0.4, abs=0.01)


def test_jacobian_matches_finite_differences(monkeypatch):
    rng = np.random.default_rng(3)
    pts = _walks(rng, n_walks=2, n=12)
    g = build_graph(pts, 2, anchors="every:5")
    g = dataclasses.replace(
        g,
        pair_i=np.array([0, 3]),
        pair_j=np.array([13, 20]),
        range_m=np.array([2.0, 30.0]),
        range_sigma_m=np.array([1.0, 2.0]),
        init_xy_m=g.init_xy_m + rng.normal(0, 1, g.init_xy_m.shape),
    )
    cap = {}

    class _Res:
        def __init__(self, x):
            self.x, self.cost, self.nfev, self.status = x, 0.0, 0, 1

    def fake(fun, x0, jac, **kw):
        cap["f"], cap["j"] = fun, jac
        return _Res(x0)

    monkeypatch.setattr(gs, "least_squares", fake)
    for loss in ("none", "huber", "cauchy"):
        gs.solve_graph_scipy(dataclasses.replace(g, loss=loss))
        x = np.concatenate([g.init_xy_m.ravel(), g.init_heading_rad, g.init_scale])
        J = cap["j"](x).toarray()
        Jn = np.zeros_like(J)
        for k in range(len(x)):
            dx = np.zeros_like(x)
            dx[k] = 1e-6
            Jn[:, k] = (cap["f"](x + dx) - cap["f"](x - dx)) / 2e-6
        assert np.abs(J - Jn).max() < 1e-5, loss


def test_drifting_bias_beats_interpolation_and_cv_prefers_a_looser_heading():
    """GIVEN a heading bias drifting 0.02 rad/s and noisy steps THEN the graph beats anchor
    interpolation by half, and the anchor cross-validation does not choose the tightest σ_θ."""
    rng = np.random.default_rng(4)
    pts = _walks(rng, n_walks=5, n=80, drift_rad_per_s=0.02)
    pts = dataclasses.replace(pts, dr_xy_m=pts.dr_xy_m + rng.normal(0, 0.05, pts.dr_xy_m.shape))
    is_anchor = np.zeros(len(pts.t_us), bool)
    for k in range(5):
        is_anchor[np.flatnonzero(pts.walk == k)[::10]] = True
    sig, rows = choose_heading_sigma(pts, 5, is_anchor, GraphSettings(), solver="scipy")
    assert len(rows) == 5 and sig > 0.02
    g = build_graph(pts, 5, anchors=is_anchor, settings=GraphSettings(heading_sigma_rad_per_sqrt_s=sig))
    sol = gs.solve_graph_scipy(g)
    assert _error(sol.xy_m, pts, g) < 0.5 * _error(g.init_xy_m, pts, g)


class _Oracle:
    """A pair model that knows the true distance (σ 0.5 m): tests the loop-closure plumbing."""

    name = "oracle"

    def __init__(self, xy_of_row):
        self.xy = xy_of_row

    def predict(self, Ra, Rb):
        a, b = self.xy[Ra[:, 0].astype(int)], self.xy[Rb[:, 0].astype(int)]
        d = np.hypot(*(a[:, None, :] - b[None, :, :]).transpose(2, 0, 1))
        return d, np.full(d.shape, 0.5)


def test_wifi_loop_closures_join_walks_and_fix_a_walk_with_one_anchor():
    rng = np.random.default_rng(5)
    # walk 3's bias is far from the other walks' (the fleet prior): only the Wi-Fi rows can tell it
    # and it walks walk 0's corridor, where the loop closures are
    pts = _walks(rng, n_walks=4, n=60, bias_rad=np.array([0.3, 0.4, 0.5, 0.9]), retrace=(3, 0))

    class _Scans:  # fingerprint row = its index (the oracle reads it back)
        R = np.arange(len(pts.t_us), dtype=float)[:, None]

    is_anchor = np.zeros(len(pts.t_us), bool)
    for k in range(3):
        is_anchor[np.flatnonzero(pts.walk == k)[::8]] = True
    is_anchor[np.flatnonzero(pts.walk == 3)[0]] = True  # walk 3: one anchor, heading unknown
    s = GraphSettings(wifi_per_point=3, wifi_max_range_m=8.0)
    g0 = build_graph(pts, 4, anchors=is_anchor, settings=s)
    i, j, d, sig = wifi_rows(pts, _Scans, _Oracle(pts.truth_xy_m), s, g0.init_xy_m)
    assert len(i) > 0 and np.all(pts.walk[i] != pts.walk[j]) and np.all(d <= 8.0)
    assert np.all(np.bincount(np.concatenate([i, j])) <= 2 * 3 + 6)
    w3 = pts.walk == 3
    assert np.sum(w3[i] | w3[j]) >= 20  # walk 3 is joined to walk 0
    e0 = gs.solve_graph_scipy(g0).xy_m
    g1 = dataclasses.replace(g0, pair_i=i, pair_j=j, range_m=d, range_sigma_m=sig)
    e1 = gs.solve_graph_scipy(g1).xy_m
    err = [float(np.mean(np.hypot(*(e[w3] - pts.truth_xy_m[w3]).T))) for e in (e0, e1)]
    assert err[0] > 2.0, err  # the heading is wrong without them
    assert err[1] < 0.5 * err[0], err
