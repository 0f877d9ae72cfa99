"""The coordinate problem and the scipy reference solver (crowd_solve) on small synthetic walks.

The 1-D thesis check lives in the native solver's tests; here: our problem construction (anchors,
PDR rows, Wi-Fi rows, filter, weights) and the scipy reference recovering a known 2-D geometry."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd.solve import (
    Problem,
    build_problem,
    error_stats,
    make_points,
    parse_anchors,
    solve,
    solve_scipy,
)
from stridefix_analyzer.crowd.walks import CrowdInputError, Walk, pool_scans

APS = np.array([[0.0, 0.0], [20.0, 0.0], [20.0, 10.0], [0.0, 10.0]])


def _walk(name, start, seed, n_steps=40, step_m=0.7):
    """A walk round a 20 × 10 m rectangle: steps every 0.5 s (exact length and heading), dense truth
    at the step times, a scan at every 4th step time with RSS = −40 − 20·log10(1 + distance to AP)
    (APs beyond 18 m not heard)."""
    corners = np.array([[0, 0], [20, 0], [20, 10], [0, 10], [0, 0]], float)
    seglen = np.hypot(*np.diff(corners, axis=0).T)
    s = (start + step_m * np.arange(n_steps + 1)) % seglen.sum()
    cum = np.concatenate([[0], np.cumsum(seglen)])
    k = np.searchsorted(cum, s, side="right") - 1
    pos = corners[k] + (s - cum[k])[:, None] * (np.diff(corners, axis=0)[k] / seglen[k][:, None])
    t = (1_000_000 + 500_000 * np.arange(n_steps + 1)).astype(np.int64)
    d = np.diff(pos, axis=0)
    scan_t = t[::4]
    scan_pos = pos[::4]
    rows, bss, rss = [], [], []
    for i, p in enumerate(scan_pos):
        for a, ap in enumerate(APS):
            dist = np.hypot(*(p - ap))
            if dist < 18:
                rows.append(i), bss.append(a + 1), rss.append(round(-40 - 20 * np.log10(1 + dist)))
    return Walk(
        name=name,
        scan_t_us=scan_t,
        ap_scan=np.array(rows),
        ap_bssid=np.array(bss),
        ap_rssi_dbm=np.array(rss, float),
        ap_freq_mhz=np.full(len(rows), 2412),
        truth_t_us=t,
        truth_xy_m=pos,
        truth_floor=np.zeros(len(t), np.int64),
        dense_truth=True,
        step_t_us=t[1:],
        step_length_m=np.hypot(*d.T),
        step_heading_rad=np.arctan2(d[:, 1], d[:, 0]) + 0.3 * seed,
    )


@pytest.fixture
def walks():
    return [_walk("a", 0.0, 0), _walk("b", 13.0, 1), _walk("c", 31.0, 2)]


def test_anchor_specs():
    assert parse_anchors("every:4") == 4 and parse_anchors("every-other-waypoint") == 2
    with pytest.raises(CrowdInputError):
        parse_anchors("every:0")


def test_pdr_rows_are_true_distances_and_anchors_every_fourth(walks):
    scans = pool_scans(walks, "all")
    pts = make_points(walks, scans)
    prob = build_problem(walks, scans, pts, model=None, ranges="pdr", anchors="every:4", pdr_span=2)
    # each walk: 11 scan points; anchors at 0, 4, 8
    assert len(prob.anchor_index) == 9
    assert_array_equal(prob.anchor_index[:3], [0, 4, 8])
    true = np.hypot(*(pts.truth_xy_m[prob.pair_i] - pts.truth_xy_m[prob.pair_j]).T)
    assert_allclose(prob.range_m, true, atol=1e-9)  # chord is heading-offset invariant
    assert np.all(np.abs(prob.pair_j - prob.pair_i) <= 2) and len(prob.pair_i) == 3 * (10 + 9)
    assert_allclose(prob.weight, 1 / (prob.range_m + 2))


def test_scipy_reference_recovers_geometry_from_exact_ranges(walks):
    scans = pool_scans(walks, "all")
    pts = make_points(walks, scans)
    prob = build_problem(walks, scans, pts, model=None, ranges="pdr", anchors="every:4", pdr_span=0)
    prob.x0 = prob.x0 + np.random.default_rng(0).normal(0, 1.0, prob.x0.shape)
    xy, info = solve_scipy(prob)
    e = error_stats(xy, pts, prob)
    assert e["n"] == 24 and e["mean_m"] < 1e-4
    assert "scipy" in info["solver"]


def test_wifi_rows_pass_the_filter_and_skip_pairs_without_common_ap(walks):
    scans = pool_scans(walks, "all")
    pts = make_points(walks, scans)
    model = cm.DistanceModel(0.5, -1.0, 0.5)
    prob = build_problem(walks, scans, pts, model=model, ranges="wifi", anchors="every:4", tau=0.45)
    info = prob.info
    assert info["wifi_pairs_no_common_ap"] > 0
    assert np.all(prob.range_m <= info["wifi_threshold_m"] + 1e-12)
    assert 0 < info["wifi_pairs"] < info["wifi_candidate_pairs"] - info["wifi_pairs_no_common_ap"]
    # without the filter: every candidate pair with a common AP
    prob2 = build_problem(
        walks, scans, pts, model=model, ranges="wifi", anchors="every:4", tau=None, weights=None
    )
    assert prob2.info["wifi_pairs"] == info["wifi_candidate_pairs"] - info["wifi_pairs_no_common_ap"]
    assert_allclose(prob2.weight, 1.0)


def test_hybrid_keeps_only_pdr_pairs_passing_the_filter(walks):
    scans = pool_scans(walks, "all")
    pts = make_points(walks, scans)
    model = cm.DistanceModel(0.5, -1.0, 0.5)
    full = build_problem(walks, scans, pts, model=model, ranges="pdr", pdr_span=0)
    hyb = build_problem(walks, scans, pts, model=model, ranges="hybrid", pdr_span=0, tau=0.45)
    assert np.all(hyb.row_kind == 0)
    assert 0 < len(hyb.pair_i) < len(full.pair_i)
    both = build_problem(walks, scans, pts, model=model, ranges="both", pdr_span=1, tau=0.45)
    assert np.sum(both.row_kind == 0) == 30 and np.sum(both.row_kind == 1) > 0


def test_wifi_ranges_need_a_model(walks):
    scans = pool_scans(walks, "all")
    with pytest.raises(CrowdInputError, match="model"):
        build_problem(walks, scans, make_points(walks, scans), model=None, ranges="wifi")


def test_native_and_scipy_agree_when_native_is_built():
    pytest.importorskip("stridefix_native")
    rng = np.random.default_rng(2)
    true = rng.uniform(0, 10, (12, 2))
    i, j = np.triu_indices(12, 1)
    b = np.hypot(*(true[i] - true[j]).T)
    a = np.arange(0, 12, 4)
    prob = Problem(
        n=12,
        anchor_index=a,
        anchor_xy=true[a],
        pair_i=i,
        pair_j=j,
        range_m=b,
        weight=1 / (b + 2),
        row_kind=np.zeros(len(i), np.int8),
        x0=true + rng.normal(0, 0.5, true.shape),
        info={},
    )
    xy_n, info_n = solve(prob, "native")
    xy_s, _ = solve(prob, "scipy")
    assert "native" in info_n["solver"]
    assert_allclose(xy_n, true, atol=1e-4)
    assert_allclose(xy_s, true, atol=1e-4)
