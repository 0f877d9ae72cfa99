"""Solvers of the crowd graph (:mod:`.graph`): Ceres (``stridefix_native.solve_graph``) and its scipy twin.

The twin minimises the same cost with ``scipy.optimize.least_squares`` (trust-region reflective, LSMR)
on an analytic sparse Jacobian. Ceres applies the robust loss ρ to a residual block's squared norm;
least_squares has one loss for every residual, so the twin applies ρ itself to the range rows by the
residual transform r̃ = sign(r)·√ρ(r²) (then ½ r̃² = ½ ρ(r²), the same cost and minimiser) with
dr̃/dr = ρ'(r²)·r / r̃ (→ 1 as r → 0). Unknown vector: x = [x_0, y_0, …, x_{n−1}, y_{n−1}, θ_0 … θ_{n−1},
s_0 … s_{W−1}].
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import least_squares

from stridefix_analyzer.crowd.graph import GraphProblem
from stridefix_analyzer.crowd.walks import CrowdInputError

SOLVERS = ("auto", "native", "scipy")


@dataclasses.dataclass
class GraphSolution:
    xy_m: np.ndarray  # (n, 2)
    heading_rad: np.ndarray  # (n,)
    scale: np.ndarray  # (W,)
    info: dict


def _rho(s: np.ndarray, loss: str, c: float) -> tuple[np.ndarray, np.ndarray]:
    """ρ(s) and ρ'(s) of Ceres's losses with scale ``c`` (s = r²)."""
    if loss == "none":
        return s, np.ones_like(s)
    c2 = c * c
    if loss == "cauchy":
        return c2 * np.log1p(s / c2), 1.0 / (1.0 + s / c2)
    root = np.sqrt(s)  # huber
    big = s > c2
    return np.where(big, 2.0 * c * root - c2, s), np.where(big, c / np.maximum(root, 1e-300), 1.0)


def _layout(g: GraphProblem):
    """Residual rows and Jacobian sparsity (rows, cols) of each block, in residual order."""
    n, W = g.n_points, g.n_walks
    th, sc = 2 * n, 3 * n
    k, h, a, r = len(g.step_i), len(g.head_i), len(g.anchor_idx), len(g.pair_i)
    i, j, w = g.step_i, g.step_j, g.step_walk
    # step rows q (x), k + q (y): depend on x_j, x_i, θ_i, s_w (x) and y_j, y_i, θ_i, s_w (y)
    q = np.arange(k)
    step_rows = np.concatenate([np.repeat(q, 4), np.repeat(k + q, 4)])
    step_cols = np.concatenate(
        [
            np.stack([2 * j, 2 * i, th + i, sc + w], 1).ravel(),
            np.stack([2 * j + 1, 2 * i + 1, th + i, sc + w], 1).ravel(),
        ]
    )
    base = 2 * k
    head_rows = np.repeat(base + np.arange(h), 2)
    head_cols = np.stack([th + g.head_j, th + g.head_i], 1).ravel()
    base += h
    scale_rows, scale_cols = base + np.arange(W), sc + np.arange(W)
    base += W
    hp = len(g.hprior_idx)
    hp_rows, hp_cols = base + np.arange(hp), th + g.hprior_idx
    base += hp
    anc_rows = base + np.arange(2 * a)
    anc_cols = np.stack([2 * g.anchor_idx, 2 * g.anchor_idx + 1], 1).ravel()
    base += 2 * a
    rng_rows = np.repeat(base + np.arange(r), 4)
    rng_cols = np.stack([2 * g.pair_i, 2 * g.pair_i + 1, 2 * g.pair_j, 2 * g.pair_j + 1], 1).ravel()
    base += r
    rows = np.concatenate([step_rows, head_rows, scale_rows, hp_rows, anc_rows, rng_rows])
    cols = np.concatenate([step_cols, head_cols, scale_cols, hp_cols, anc_cols, rng_cols])
    return rows, cols, base, 3 * n + W


def _model(g: GraphProblem):
    """The twin's residual function and sparse Jacobian of x, and x's unpacking (module docstring)."""
    n = g.n_points
    i, j, w, d = g.step_i, g.step_j, g.step_walk, g.step_dxy_m
    ss, hs = g.step_sigma_m, g.head_sigma_rad
    pi, pj, b, bs = g.pair_i, g.pair_j, g.range_m, g.range_sigma_m
    rows, cols, m, nx = _layout(g)

    def unpack(x):
        return x[: 2 * n].reshape(n, 2), x[2 * n : 3 * n], x[3 * n :]

    def parts(x):
        p, th, s = unpack(x)
        c, sn = np.cos(th[i]), np.sin(th[i])
        rx = s[w] * (c * d[:, 0] - sn * d[:, 1])
        ry = s[w] * (sn * d[:, 0] + c * d[:, 1])
        dp = p[pi] - p[pj]
        dist = np.hypot(dp[:, 0], dp[:, 1])
        rr = (b - dist) / bs
        rho, drho = _rho(rr * rr, g.loss, g.loss_scale)
        rt = np.sign(rr) * np.sqrt(rho)
        return p, th, s, c, sn, rx, ry, dp, dist, rr, rt, drho

    def fun(x):
        p, th, s, c, sn, rx, ry, dp, dist, rr, rt, drho = parts(x)
        step = ((p[j] - p[i]) - np.column_stack([rx, ry])) / ss[:, None]
        return np.concatenate(
            [
                step[:, 0],
                step[:, 1],
                (th[g.head_j] - th[g.head_i]) / hs,
                (s - g.scale_prior) / g.scale_sigma,
                (th[g.hprior_idx] - g.hprior_rad) / g.hprior_sigma_rad,
                ((p[g.anchor_idx] - g.anchor_xy_m) / g.anchor_sigma_m[:, None]).ravel(),
                rt,
            ]
        )

    def jac(x):
        p, th, s, c, sn, rx, ry, dp, dist, rr, rt, drho = parts(x)
        inv = 1.0 / ss
        # ∂(s R(θ) d)/∂θ = s·(−sin θ dx − cos θ dy, cos θ dx − sin θ dy) = (−ry, rx)
        dx_dth, dy_dth = ry * inv, -rx * inv
        ux_s = -(c * d[:, 0] - sn * d[:, 1]) * inv
        uy_s = -(sn * d[:, 0] + c * d[:, 1]) * inv
        vx = np.stack([inv, -inv, dx_dth, ux_s], 1).ravel()
        vy = np.stack([inv, -inv, dy_dth, uy_s], 1).ravel()
        vh = np.stack([1.0 / hs, -1.0 / hs], 1).ravel()
        vs = 1.0 / g.scale_sigma  # (W,)
        va = np.repeat(1.0 / g.anchor_sigma_m, 2)
        with np.errstate(invalid="ignore", divide="ignore"):
            f = np.where(np.abs(rt) > 1e-12, drho * rr / rt, 1.0)
        safe = np.maximum(dist, 1e-12)
        ux = np.where(dist >= 1e-12, dp[:, 0] / safe, -1.0)
        uy = np.where(dist >= 1e-12, dp[:, 1] / safe, 0.0)
        k = -f / bs  # ∂r/∂p_i = −u/σ, ∂r/∂p_j = +u/σ
        vr = np.stack([k * ux, k * uy, -k * ux, -k * uy], 1).ravel()
        vals = np.concatenate([vx, vy, vh, vs, 1.0 / g.hprior_sigma_rad, va, vr])
        return sp.csr_matrix((vals, (rows, cols)), shape=(m, nx))

    return fun, jac, unpack


def solve_graph_scipy(g: GraphProblem, max_nfev: int = 1000) -> GraphSolution:
    """The scipy twin (module docstring)."""
    fun, jac, unpack = _model(g)
    x0 = np.concatenate([g.init_xy_m.ravel(), g.init_heading_rad, g.init_scale])
    t0 = time.perf_counter()
    res = least_squares(fun, x0, jac=jac, method="trf", tr_solver="lsmr", x_scale=1.0, max_nfev=max_nfev)
    p, th, s = unpack(res.x)
    return GraphSolution(
        p.copy(),
        th.copy(),
        s.copy(),
        {
            "solver": "scipy least_squares (trf, lsmr)",
            "cost": float(res.cost),
            "initial_cost": float(0.5 * np.sum(fun(x0) ** 2)),
            "iterations": int(res.nfev),
            "converged": bool(res.status > 0),
            "solve_s": time.perf_counter() - t0,
        },
    )


def position_sigma_m(g: GraphProblem, sol: GraphSolution, chunk: int = 512) -> np.ndarray:
    """Radial posterior σ [m] of each point, √(Σ_xx + Σ_yy), Σ the Gauss-Newton covariance (JᵀJ)⁻¹
    at ``sol`` (rows already divided by their σ; range rows at their robust weight).

    Taken walk by walk: exact when no row joins two walks (anchors + steps), and with Wi-Fi rows the
    σ given the other walks' points (those rows' information on this walk only). Cost: one sparse LU
    per walk and 2 solves per point, in chunks of ``chunk`` columns."""
    _, jac, _ = _model(g)
    n = g.n_points
    J = jac(np.concatenate([sol.xy_m.ravel(), sol.heading_rad, sol.scale])).tocsc()
    walk = np.zeros(n, np.int64)
    walk[g.step_i] = g.step_walk
    walk[g.step_j] = g.step_walk
    out = np.full(n, np.nan)
    for k in range(g.n_walks):
        ids = np.flatnonzero(walk == k)
        if len(ids) == 0:
            continue
        # one point's (x, y, θ) next to each other, the walk's scale last: a banded chain for the LU
        cols = np.concatenate([np.stack([2 * ids, 2 * ids + 1, 2 * n + ids], 1).ravel(), [3 * n + k]])
        Jw = J[:, cols]
        H = (Jw.T @ Jw).tocsc()
        try:
            lu = spla.splu(H)
        except RuntimeError:  # singular: a point no row constrains has no finite σ
            continue
        m = 3 * len(ids) + 1
        var = np.zeros(len(ids))
        for a in range(0, len(ids), chunk):
            sel = np.arange(a, min(a + chunk, len(ids)))
            for off in (0, 1):  # x, y
                rhs = np.zeros((m, len(sel)))
                rhs[3 * sel + off, np.arange(len(sel))] = 1.0
                var[sel] += lu.solve(rhs)[3 * sel + off, np.arange(len(sel))]
        out[ids] = np.sqrt(np.maximum(var, 0.0))
    return out


def solve_graph_native(g: GraphProblem, max_iterations: int = 200) -> GraphSolution:
    """``stridefix_native.solve_graph`` (C++/Ceres); raises when it is missing or fails."""
    import stridefix_native  # noqa: PLC0415 - optional

    t0 = time.perf_counter()
    out = stridefix_native.solve_graph(
        g.n_points,
        g.n_walks,
        g.step_i,
        g.step_j,
        g.step_walk,
        g.step_dxy_m,
        g.step_sigma_m,
        g.head_i,
        g.head_j,
        g.head_sigma_rad,
        g.scale_prior,
        g.scale_sigma,
        g.hprior_idx,
        g.hprior_rad,
        g.hprior_sigma_rad,
        g.anchor_idx,
        g.anchor_xy_m,
        g.anchor_sigma_m,
        g.pair_i,
        g.pair_j,
        g.range_m,
        g.range_sigma_m,
        loss=g.loss,
        loss_scale=g.loss_scale,
        init_xy=g.init_xy_m,
        init_heading_rad=g.init_heading_rad,
        init_scale=g.init_scale,
        max_iterations=int(max_iterations),
    )
    return GraphSolution(
        np.asarray(out["xy"], float).reshape(g.n_points, 2),
        np.asarray(out["heading_rad"], float),
        np.asarray(out["scale"], float),
        {
            "solver": "stridefix_native.solve_graph (Ceres)",
            "cost": out.get("cost"),
            "initial_cost": out.get("initial_cost"),
            "iterations": out.get("iterations"),
            "converged": out.get("converged"),
            "message": out.get("message"),
            "solve_s": time.perf_counter() - t0,
        },
    )


def solve_graph(g: GraphProblem, solver: str = "auto") -> GraphSolution:
    """Solve with ``solver`` (auto = Ceres when importable, else scipy); the info says which ran."""
    if solver not in SOLVERS:
        raise CrowdInputError(f"solver {solver!r} not one of {SOLVERS}")
    note = None
    if solver in ("auto", "native"):
        try:
            sol = solve_graph_native(g)
            if not np.all(np.isfinite(sol.xy_m)):
                raise ValueError("non-finite positions")
            return sol
        except Exception as exc:  # noqa: BLE001 - any native failure falls back (reported)
            if solver == "native":
                raise CrowdInputError(f"native graph solver unavailable or failed: {exc!r}") from exc
            note = f"native solver not used ({type(exc).__name__}: {str(exc)[:200]})"
    sol = solve_graph_scipy(g)
    if note:
        sol.info["note"] = note
    return sol
