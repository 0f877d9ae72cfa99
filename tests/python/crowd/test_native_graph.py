"""The native crowd graph solver (``stridefix_native.solve_graph``, analyzer/native/sf_graph_solver.cpp,
Ceres) against its scipy twin (``crowd.graph_solve.solve_graph_scipy``) and against the truth of a
synthetic crowd: walks with a known stride scale (1.1) and a drifting heading bias (0.3 rad + drift),
anchors every 4th point, Wi-Fi loop closures between walks, two of them gross outliers.

Skipped when the importable ``stridefix_native`` has no ``solve_graph`` (an older build).
Run as a script for the Ceres vs scipy timing: ``python tests/python/crowd/test_native_graph.py 5000 50000``.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import pytest
from stridefix_analyzer.crowd.graph import FleetPriors, GraphProblem, GraphSettings, build_graph
from stridefix_analyzer.crowd.graph_solve import GraphSolution, solve_graph_native, solve_graph_scipy
from stridefix_analyzer.crowd.solve import Points

try:
    import stridefix_native as _sn

    HAVE_GRAPH = hasattr(_sn, "solve_graph")
except ImportError:  # pragma: no cover - depends on the build
    HAVE_GRAPH = False

pytestmark = pytest.mark.skipif(not HAVE_GRAPH, reason="stridefix_native has no solve_graph (rebuild)")

SCALE_TRUE = 1.1
BIAS_TRUE_RAD = 0.3


def _truth_walk(rng: np.random.Generator, n: int, start_xy_m: np.ndarray) -> np.ndarray:
    """(n, 2) positions [m] of a walker at ~1.2 m/s, 1 s apart, turning smoothly, inside ~40 m."""
    psi = rng.uniform(0, 2 * np.pi) + np.cumsum(rng.normal(0.0, 0.15, n)) + 0.5 * np.sin(np.arange(n) / 9.0)
    step = 1.2 * np.c_[np.cos(psi), np.sin(psi)]
    xy = start_xy_m + np.vstack([np.zeros(2), np.cumsum(step[:-1], axis=0)])
    # fold back into a 40 m square so the walks share the place (loop closures need neighbours)
    return 40.0 - np.abs(40.0 - np.abs(xy) % 80.0)


def synthetic(
    n_walks: int = 3,
    n_per_walk: int = 100,
    *,
    seed: int = 1,
    exact: bool = False,
    n_wifi: int = 30,
    n_outliers: int = 2,
    dr_sigma_m: float = 0.05,
    loss: str = "cauchy",
) -> tuple[GraphProblem, Points, np.ndarray, np.ndarray]:
    """The graph of a synthetic crowd (module docstring) via :func:`build_graph`, its points, the true
    heading bias per point [rad] and the row indices of the outlier Wi-Fi rows.

    ``exact``: no DR noise, a constant bias, no Wi-Fi noise, no outliers and the scale and heading
    priors at the truth, so the truth has cost 0."""
    rng = np.random.default_rng(seed)
    walk, t_us, truth, dr, bias = [], [], [], [], []
    for w in range(n_walks):
        xy = _truth_walk(rng, n_per_walk, rng.uniform(5.0, 35.0, 2))
        if exact:
            th = np.full(n_per_walk, BIAS_TRUE_RAD)
        else:  # a slow random walk of the bias around 0.3 rad (~0.1 rad over a walk)
            th = BIAS_TRUE_RAD + np.cumsum(rng.normal(0.0, 0.01, n_per_walk))
        dp = np.diff(xy, axis=0)
        c, s = np.cos(th[:-1]), np.sin(th[:-1])
        # the DR displacement d with s·R(θ)·d = true displacement: d = R(−θ)·dp / s
        d = np.c_[c * dp[:, 0] + s * dp[:, 1], -s * dp[:, 0] + c * dp[:, 1]] / SCALE_TRUE
        if not exact:
            d = d + rng.normal(0.0, dr_sigma_m, d.shape)
        walk.append(np.full(n_per_walk, w))
        t_us.append(np.arange(n_per_walk, dtype=np.int64) * 1_000_000)
        truth.append(xy)
        dr.append(np.vstack([np.zeros(2), np.cumsum(d, axis=0)]))
        bias.append(th)
    xy_true = np.concatenate(truth)
    dr_xy = np.concatenate(dr)
    n = len(xy_true)
    wk = np.concatenate(walk)
    path = np.zeros(n)
    same = wk[1:] == wk[:-1]
    path[1:] = np.where(same, np.hypot(*np.diff(dr_xy, axis=0).T), 0.0)
    points = Points(
        walk=wk,
        t_us=np.concatenate(t_us),
        is_scan=np.ones(n, bool),
        fp=np.arange(n),
        truth_xy_m=xy_true,
        floor=np.zeros(n, np.int64),
        is_truth=np.ones(n, bool),
        dr_xy_m=dr_xy,
        dr_path_m=path,
    )
    # Wi-Fi loop closures: random points to their nearest point of another walk, when within 10 m
    wi, wj, wb = [], [], []
    for i in rng.permutation(n):
        if len(wi) >= n_wifi:
            break
        other = np.flatnonzero(wk != wk[i])
        dist = np.hypot(*(xy_true[other] - xy_true[i]).T)
        k = int(np.argmin(dist))
        if dist[k] <= 10.0:
            wi.append(i)
            wj.append(other[k])
            wb.append(dist[k] if exact else abs(dist[k] + rng.normal(0.0, 0.3)))
    outl = []
    for _ in range(0 if exact else n_outliers):  # a far place that looks near: 1 m claimed, >= 25 m true
        while True:
            i, j = rng.integers(0, n, 2)
            if wk[i] != wk[j] and np.hypot(*(xy_true[i] - xy_true[j])) >= 25.0:
                break
        outl.append(len(wi))
        wi.append(i)
        wj.append(j)
        wb.append(1.0)
    rows = (np.array(wi, np.int64), np.array(wj, np.int64), np.array(wb), np.full(len(wi), 1.0))
    g = build_graph(
        points,
        n_walks,
        anchors="every:4",
        settings=GraphSettings(loss=loss),
        # exact: the scale and heading priors at the truth (a constant bias on every walk)
        priors=FleetPriors(scale=SCALE_TRUE, heading_rad=BIAS_TRUE_RAD) if exact else FleetPriors(scale=1.0),
        wifi_rows=rows,
    )
    return g, points, np.concatenate(bias), np.array(outl, np.int64)


def _err_m(sol: GraphSolution, points: Points) -> np.ndarray:
    return np.hypot(*(sol.xy_m - points.truth_xy_m).T)


# --- (a) Ceres and the scipy twin minimise the same cost ---------------------------------------------


@pytest.mark.parametrize("loss", ["cauchy", "huber", "none"])
def test_ceres_and_scipy_twin_agree(loss):
    g, _, _, _ = synthetic(loss=loss)
    assert len(g.hprior_idx) == g.n_walks  # every row kind is compared, the heading priors too
    nat = solve_graph_native(g)
    ref = solve_graph_scipy(g, max_nfev=2000)
    assert nat.info["converged"], nat.info["message"]
    assert abs(nat.info["initial_cost"] - ref.info["initial_cost"]) <= 1e-9 * ref.info["initial_cost"]
    assert np.max(np.hypot(*(nat.xy_m - ref.xy_m).T)) < 1e-3
    assert np.max(np.abs(nat.heading_rad - ref.heading_rad)) < 1e-4
    assert np.max(np.abs(nat.scale - ref.scale)) < 1e-5
    assert abs(nat.info["cost"] - ref.info["cost"]) <= 1e-6 * ref.info["cost"]
    assert nat.info["cost"] < nat.info["initial_cost"]


def test_empty_rows_work():
    """No Wi-Fi rows, no anchors: steps, heading and scale only (the start stays up to a rigid motion)."""
    g, _, _, _ = synthetic(n_wifi=0, n_outliers=0)
    empty_i, empty_f = np.zeros(0, np.int64), np.zeros(0)
    g.pair_i = g.pair_j = g.anchor_idx = empty_i
    g.range_m = g.range_sigma_m = g.anchor_sigma_m = empty_f
    g.anchor_xy_m = np.zeros((0, 2))
    nat = solve_graph_native(g)
    ref = solve_graph_scipy(g, max_nfev=2000)
    assert nat.info["converged"], nat.info["message"]
    assert abs(nat.info["cost"] - ref.info["cost"]) <= 1e-6 * max(ref.info["cost"], 1e-12) + 1e-9


def test_nothing_to_solve_returns_the_start():
    e_i, e_f = np.zeros(0, np.int64), np.zeros(0)
    out = _sn.solve_graph(
        *(1, 0, e_i, e_i, e_i, np.zeros((0, 2)), e_f, e_i, e_i, e_f, e_f, e_f, e_i, e_f, e_f),
        *(e_i, np.zeros((0, 2)), e_f),
        *(e_i, e_i, e_f, e_f),
        init_xy=np.array([[2.0, 3.0]]),
        init_heading_rad=np.array([0.5]),
        init_scale=e_f,
    )
    assert out["iterations"] == 0 and out["cost"] == 0.0
    np.testing.assert_array_equal(out["xy"], [[2.0, 3.0]])
    assert out["heading_rad"].tolist() == [0.5] and out["scale"].shape == (0,)


# --- (b) the unknowns come back ----------------------------------------------------------------------


def test_recovers_scale_and_heading_bias():
    g, points, bias, _ = synthetic()
    sol = solve_graph_native(g)
    assert np.all(np.abs(sol.scale - SCALE_TRUE) < 0.05), sol.scale
    for w in range(g.n_walks):
        m = points.walk == w
        assert abs(np.mean(sol.heading_rad[m] - bias[m])) < 0.05
        assert np.max(np.abs(sol.heading_rad[m] - bias[m])) < 0.2
    assert np.sqrt(np.mean(_err_m(sol, points) ** 2)) < 0.5


# --- (c) the robust loss ------------------------------------------------------------------------------


def test_cauchy_keeps_outliers_from_pulling_points():
    g, points, _, outl = synthetic(loss="cauchy")
    bad = np.unique(np.r_[g.pair_i[outl], g.pair_j[outl]])
    cauchy = _err_m(solve_graph_native(g), points)
    g.loss = "none"
    plain = _err_m(solve_graph_native(g), points)
    assert np.max(cauchy[bad]) < 1.0
    assert np.max(plain[bad]) > 2.0 * np.max(cauchy[bad])
    assert np.sqrt(np.mean(plain**2)) > np.sqrt(np.mean(cauchy**2))


# --- (d) validation ------------------------------------------------------------------------------------


def _kwargs(g: GraphProblem) -> dict:
    return dict(
        n_points=g.n_points,
        n_walks=g.n_walks,
        step_i=g.step_i,
        step_j=g.step_j,
        step_walk=g.step_walk,
        step_dxy_m=g.step_dxy_m,
        step_sigma_m=g.step_sigma_m,
        head_i=g.head_i,
        head_j=g.head_j,
        head_sigma_rad=g.head_sigma_rad,
        scale_prior=g.scale_prior,
        scale_sigma=g.scale_sigma,
        hprior_idx=g.hprior_idx,
        hprior_rad=g.hprior_rad,
        hprior_sigma_rad=g.hprior_sigma_rad,
        anchor_idx=g.anchor_idx,
        anchor_xy_m=g.anchor_xy_m,
        anchor_sigma_m=g.anchor_sigma_m,
        pair_i=g.pair_i,
        pair_j=g.pair_j,
        range_m=g.range_m,
        range_sigma_m=g.range_sigma_m,
        loss=g.loss,
        loss_scale=g.loss_scale,
        init_xy=g.init_xy_m,
        init_heading_rad=g.init_heading_rad,
        init_scale=g.init_scale,
    )


def test_validation_lists_every_value_problem():
    g, _, _, _ = synthetic(n_walks=2, n_per_walk=60, n_wifi=5, n_outliers=0)
    kw = _kwargs(g)
    kw["step_i"] = g.step_i.copy()
    kw["step_i"][3] = g.n_points + 5  # out of range
    kw["step_walk"] = g.step_walk.copy()
    kw["step_walk"][0] = g.n_walks  # no such walk
    kw["head_sigma_rad"] = g.head_sigma_rad.copy()
    kw["head_sigma_rad"][1] = 0.0
    kw["pair_j"] = g.pair_i.copy()  # every pair joins a point to itself
    kw["range_sigma_m"] = np.full(len(g.range_m), np.nan)
    kw["anchor_xy_m"] = g.anchor_xy_m[:-1]  # one row short
    kw["scale_sigma"] = -g.scale_sigma
    kw["init_heading_rad"] = g.init_heading_rad[:-2]
    kw["hprior_sigma_rad"] = np.zeros(len(g.hprior_idx))
    kw["loss"] = "tukey"
    kw["loss_scale"] = 0.0
    with pytest.raises(ValueError) as e:
        _sn.solve_graph(**kw)
    msg = str(e.value)
    for name in (
        "step_i",
        "step_walk",
        "head_sigma_rad",
        "pairs",
        "range_sigma_m",
        "anchor_xy_m",
        "scale_sigma",
        "init_heading_rad",
        "hprior_sigma_rad",
        "loss must be",
        "loss_scale",
    ):
        assert name in msg, (name, msg)
    assert "11 problem(s)" in msg, msg


def test_validation_lists_every_shape_and_dtype_problem():
    g, _, _, _ = synthetic(n_walks=2, n_per_walk=60, n_wifi=5, n_outliers=0)
    kw = _kwargs(g)
    kw["step_i"] = g.step_i.astype(float)  # indices must be integers
    kw["step_dxy_m"] = g.step_dxy_m.ravel()  # must be (k, 2)
    kw["init_xy"] = np.zeros((g.n_points, 3))
    kw["pair_i"] = "abc"
    with pytest.raises(ValueError) as e:
        _sn.solve_graph(**kw)
    msg = str(e.value)
    for name in ("step_i", "step_dxy_m", "init_xy", "pair_i"):
        assert name in msg, (name, msg)
    assert "4 problem(s)" in msg, msg


def test_step_joining_a_point_to_itself_is_refused_not_a_crash():
    g, _, _, _ = synthetic(n_walks=2, n_per_walk=20, n_wifi=0, n_outliers=0)
    kw = _kwargs(g)
    kw["step_j"] = g.step_i.copy()
    kw["head_j"] = g.head_i.copy()
    with pytest.raises(ValueError, match=r"(?s)steps: \d+ row.*heading rows: \d+ row"):
        _sn.solve_graph(**kw)


# --- (e) exact data ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("loss", ["cauchy", "none"])
def test_exact_data_converges_to_the_truth(loss):
    g, points, bias, _ = synthetic(exact=True, loss=loss)
    assert np.max(_err_m(GraphSolution(g.init_xy_m, g.init_heading_rad, g.init_scale, {}), points)) > 0.5
    sol = solve_graph_native(g)
    assert sol.info["converged"], sol.info["message"]
    assert np.max(_err_m(sol, points)) < 1e-6
    assert np.max(np.abs(sol.heading_rad - bias)) < 1e-6
    assert np.max(np.abs(sol.scale - SCALE_TRUE)) < 1e-6
    assert sol.info["cost"] < 1e-12


# --- the GIL is released ------------------------------------------------------------------------------


def test_threads_solve_in_parallel_and_agree():
    from concurrent.futures import ThreadPoolExecutor  # noqa: PLC0415

    g, _, _, _ = synthetic()
    one = solve_graph_native(g)
    with ThreadPoolExecutor(2) as ex:
        sols = list(ex.map(lambda _: solve_graph_native(g), range(4)))
    for s in sols:
        np.testing.assert_array_equal(s.xy_m, one.xy_m)


# --- timing (script) ------------------------------------------------------------------------------------


def _timing(n_points: int) -> None:
    """Ceres vs scipy on a synthetic crowd of ``n_points`` (walks of 500 points, ~1 Wi-Fi row per 5)."""
    n_walks = max(1, n_points // 500)
    t0 = time.perf_counter()
    g, points, _, _ = synthetic(n_walks, n_points // n_walks, n_wifi=n_points // 5, n_outliers=n_walks // 2)
    print(f"n={g.n_points} rows={g.rows()} built in {time.perf_counter() - t0:.1f} s")
    for name, run in (
        ("ceres", lambda: solve_graph_native(g)),
        ("scipy", lambda: solve_graph_scipy(g, 2000)),
    ):
        t0 = time.perf_counter()
        sol = run()
        wall = time.perf_counter() - t0
        rmse = float(np.sqrt(np.mean(_err_m(sol, points) ** 2)))
        print(
            f"  {name}: {wall:.2f} s wall, cost {sol.info['cost']:.6f} (from {sol.info['initial_cost']:.1f}), "
            f"iterations {sol.info['iterations']}, converged {sol.info['converged']}, rmse {rmse:.3f} m"
        )


if __name__ == "__main__":
    for arg in sys.argv[1:] or ["5000"]:
        _timing(int(arg))
