"""Posterior σ of the crowd graph's positions (graph_solve.position_sigma_m) and the scans it keeps
out of a crowd map (sites.drop_uncertain_scans)."""

from __future__ import annotations

import dataclasses

import numpy as np
from stridefix_analyzer.crowd import graph_solve as gs
from stridefix_analyzer.crowd.graph import FleetPriors, GraphSettings, build_graph
from stridefix_analyzer.crowd.sites import drop_uncertain_scans
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.radiomap.recordings import Recording

from .test_crowd_graph import _walks

SETTINGS = GraphSettings(heading_sigma_rad_per_sqrt_s=0.02, loss="none")
PRIORS = FleetPriors(scale=1.1, scale_sigma=0.05, heading_rad=0.4, heading_sigma_rad=0.1, walks_used=5)


def _noisy(pts, rng, scale, bias_rad):
    """``pts`` with DR drawn from the graph's own noise model: per step an isotropic error of
    σ_step (walk frame) and a heading bias that random-walks at σ_θ, around ``scale`` and ``bias_rad``."""
    tr = pts.truth_xy_m
    step = np.diff(tr, axis=0)
    d_true = np.hypot(step[:, 0], step[:, 1]) / scale
    dt_s = np.diff(pts.t_us) * 1e-6
    bias = bias_rad + np.concatenate(
        [[0.0], np.cumsum(rng.normal(0, SETTINGS.heading_sigma_rad_per_sqrt_s * np.sqrt(dt_s[:-1])))]
    )
    c, s = np.cos(-bias), np.sin(-bias)
    d = np.column_stack([c * step[:, 0] - s * step[:, 1], s * step[:, 0] + c * step[:, 1]]) / scale
    sig = SETTINGS.step_sigma0_m + SETTINGS.step_sigma_per_m * d_true
    d = d + rng.normal(0, 1, d.shape) * sig[:, None]
    dr = np.vstack([[0.0, 0.0], np.cumsum(d, axis=0)])
    return dataclasses.replace(pts, dr_xy_m=dr)


def test_sigma_is_the_dense_inverse_and_smallest_at_the_anchors():
    """GIVEN two independent walks (anchors + steps, no row between them)
    THEN the per-walk σ equals √(Σxx + Σyy) of the whole problem's dense (JᵀJ)⁻¹, is near the
    anchor σ at the anchors and grows between them."""
    pts = _walks(np.random.default_rng(5), n_walks=2, n=41)
    g = build_graph(pts, 2, anchors="every:10", settings=SETTINGS, priors=PRIORS)
    sol = gs.solve_graph_scipy(g)
    sigma = gs.position_sigma_m(g, sol, chunk=7)  # chunks smaller than a walk: the batching is exercised
    _, jac, _ = gs._model(g)
    J = jac(np.concatenate([sol.xy_m.ravel(), sol.heading_rad, sol.scale])).toarray()
    cov = np.linalg.inv(J.T @ J)
    n = g.n_points
    var = np.diag(cov)[: 2 * n].reshape(n, 2)
    dense = np.sqrt(var[:, 0] + var[:, 1])
    np.testing.assert_allclose(sigma, dense, rtol=1e-6)
    at_anchor = sigma[g.anchor_idx]
    assert np.all(at_anchor < 1.5 * SETTINGS.anchor_sigma_m)
    mid = g.anchor_idx[:-1] + 5  # halfway between two anchors of the first walk
    mid = mid[mid < 41]
    assert np.all(sigma[mid] > 1.5 * sigma[g.anchor_idx[: len(mid)]])


def test_sigma_matches_the_spread_of_repeated_solves():
    """GIVEN 150 walks drawn from the graph's own noise model (scale, bias from the priors)
    THEN the RMS radial error of the solved positions is within 20 % of the predicted σ, pooled
    over the non-anchor points (the σ a crowd map trusts is the error it gets)."""
    rng = np.random.default_rng(7)
    base = _walks(rng, n_walks=1, n=31)
    err2, sig2 = [], []
    for _ in range(150):
        scale = rng.normal(PRIORS.scale, PRIORS.scale_sigma)
        bias = rng.normal(PRIORS.heading_rad, PRIORS.heading_sigma_rad)
        pts = _noisy(base, rng, scale, bias)
        g = build_graph(pts, 1, anchors="every:10", settings=SETTINGS, priors=PRIORS)
        sol = gs.solve_graph_scipy(g)
        free = np.ones(g.n_points, bool)
        free[g.anchor_idx] = False
        err2.append(np.sum((sol.xy_m[free] - pts.truth_xy_m[free]) ** 2, axis=1))
        sig2.append(gs.position_sigma_m(g, sol)[free] ** 2)
    rms_err, rms_sig = np.sqrt(np.mean(err2)), np.sqrt(np.mean(sig2))
    assert 0.8 < rms_err / rms_sig < 1.2, (rms_err, rms_sig)


def _recording(n_scans=5):
    wifi = Table(
        {
            "t_us": np.arange(n_scans, dtype=np.int64) * 1_000_000,
            "scan_id": np.arange(n_scans),
            "complete": np.ones(n_scans, bool),
            "n_ap": np.full(n_scans, 2),
        }
    )
    ap = Table(
        {
            "scan_row": np.repeat(np.arange(n_scans), 2),
            "bssid": np.tile([11, 22], n_scans),
            "rssi_dbm": -40.0 - np.arange(2 * n_scans, dtype=float),
            "freq_mhz": np.full(2 * n_scans, 2412),
        }
    )
    truth = Table(
        {"t_us": np.array([0, 10_000_000]), "x_m": np.zeros(2), "y_m": np.zeros(2), "floor": np.zeros(2)}
    )
    return Recording(["w"], wifi, ap, truth)


def test_drop_uncertain_scans_keeps_ap_rows_with_their_scans():
    rec = _recording()
    kept, dropped = drop_uncertain_scans(rec, np.array([1.0, 9.0, 2.0, np.nan, 3.0]), 5.0)
    assert dropped == 2  # σ 9 m and an unknown σ
    assert list(kept.wifi["t_us"]) == [0, 2_000_000, 4_000_000]
    assert list(kept.wifi_ap["scan_row"]) == [0, 0, 1, 1, 2, 2]
    assert list(kept.wifi_ap["rssi_dbm"]) == [-40.0, -41.0, -44.0, -45.0, -48.0, -49.0]
    same, none = drop_uncertain_scans(rec, np.full(5, np.nan), np.inf)
    assert none == 0 and same is rec  # no limit: nothing dropped, not even an unknown σ
