"""Pure-Python reference for the native Kannan coordinate solver (``stridefix_native``), on scipy.

Same problem as ``analyzer/native/sf_coord_solver.h``: unknown 2-D points p_i (metres),

* anchor rows  ``p_i - a_i``                      (2 residuals each, weight 1),
* range rows   ``w_k * (b_k - |p_I - p_J|)``       with ``w_k = 1 / (m * b_k + c)`` (thesis m = 1, c = 2 m),
* cost ``1/2 sum |anchor r|^2 + 1/2 sum rho(range r^2)``, rho = none | huber | cauchy on range rows only,

the same default start and the same Jacobian convention at ``|p_I - p_J| = 0`` (p_J east of p_I), solved by
``scipy.optimize.least_squares(method="trf")``. It exists to cross-check the Ceres solver and to time it
(``stridefix-lab bench native-solver``); it is not meant to be fast. Also here: a synthetic walk
problem (:func:`make_problem`).

Built into ``build/analyzer/native/`` beside ``stridefix_native`` (CMake copies it), so one path entry
imports both. Reference: Kannan (2024), MSc thesis, Tampere University, section 4.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import sparse
from scipy.optimize import least_squares

MIN_DIST_M = 1e-12  # below this |p_I - p_J|, p_J - p_I is taken as +x (east), as in sf_coord_solver.h
_LOSSES = ("none", "huber", "cauchy")


def thesis_weights(ranges_m, weight_slope=1.0, weight_intercept_m=2.0):
    """Residual multipliers ``w_k = 1 / (m * b_k + c)`` in 1/m, shape (m,); ValueError unless all > 0."""
    b = np.asarray(ranges_m, dtype=float).reshape(-1)
    denom = weight_slope * b + weight_intercept_m
    with np.errstate(divide="ignore"):
        w = 1.0 / denom
    bad = ~(denom > 0) | ~np.isfinite(w)
    if bad.any():
        raise ValueError(
            f"weight law 1/(m*b + c) with m={weight_slope}, c={weight_intercept_m} gives "
            f"{int(bad.sum())} non-positive or non-finite weight(s); need c > -m*min(b)"
        )
    return w


def default_init(n_points, anchors_idx, anchors_xy):
    """Default start, shape (n_points, 2): anchors at their positions (mean if repeated), other points
    linearly interpolated in index order between the nearest anchors, constant beyond the ends."""
    idx = np.asarray(anchors_idx, dtype=np.int64).reshape(-1)
    a_xy = np.asarray(anchors_xy, dtype=float).reshape(-1, 2)
    if idx.size == 0:
        raise ValueError("the default start needs at least one anchor (or pass init_xy)")
    if idx.min() < 0 or idx.max() >= n_points:
        raise ValueError(f"anchor index outside 0..{n_points - 1}")
    count = np.bincount(idx, minlength=n_points)
    known = np.flatnonzero(count)
    t = np.arange(n_points, dtype=float)
    xy = np.empty((n_points, 2))
    for d in range(2):
        mean_d = np.bincount(idx, weights=a_xy[:, d], minlength=n_points)[known] / count[known]
        xy[:, d] = np.interp(t, known.astype(float), mean_d)  # np.interp holds the end values
    return xy


def _loss(name, scale, n_anchor_rows):
    """scipy callable loss: identity on the anchor rows, rho(z/C^2)*C^2 on the range rows (Ceres's form)."""
    if name == "none":
        return "linear"
    c2 = float(scale) ** 2

    def loss(z):
        rho = np.empty((3, z.size))
        rho[0], rho[1], rho[2] = z, 1.0, 0.0
        s = z[n_anchor_rows:] / c2
        if name == "huber":
            big = s > 1.0
            sq = np.sqrt(np.where(big, s, 1.0))
            r0 = np.where(big, 2.0 * sq - 1.0, s)
            r1 = np.where(big, 1.0 / sq, 1.0)
            r2 = np.where(big, -0.5 / (sq * sq * sq), 0.0)
        else:  # cauchy
            r0 = np.log1p(s)
            r1 = 1.0 / (1.0 + s)
            r2 = -r1 * r1
        rho[0, n_anchor_rows:] = c2 * r0
        rho[1, n_anchor_rows:] = r1
        rho[2, n_anchor_rows:] = r2 / c2
        return rho

    return loss


def solve_coordinates_ref(
    n_points,
    anchors_idx,
    anchors_xy,
    pairs,
    ranges_m,
    weights=None,
    *,
    weight_slope=None,
    weight_intercept_m=None,
    init_xy=None,
    robust_loss="none",
    loss_scale=1.0,
    max_iterations=200,
    function_tolerance=1e-10,
    gradient_tolerance=1e-12,
    parameter_tolerance=1e-10,
    use_sparse=None,
    lsmr_tol=None,
):
    """The scipy twin of ``stridefix_native.solve_coordinates`` (same arguments and result keys).

    ``use_sparse``: sparse Jacobian with the LSMR trust-region solver (default when n_points > 300), else
    a dense Jacobian with the exact trust-region solver. ``lsmr_tol``: LSMR's atol and btol (scipy's
    default 1e-6 when None); LSMR's inexact steps stall short of tight tolerances unless it is small
    (1e-14 for a cross-check to 1e-6 m). ``time_s`` is the least_squares wall time."""
    if robust_loss not in _LOSSES:
        raise ValueError(f"robust_loss must be one of {_LOSSES}, got {robust_loss!r}")
    n = int(n_points)
    a_idx = np.asarray(anchors_idx, dtype=np.int64).reshape(-1)
    a_xy = np.asarray(anchors_xy, dtype=float).reshape(-1, 2)
    pr = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    b = np.asarray(ranges_m, dtype=float).reshape(-1)
    if weights is not None:
        if weight_slope is not None or weight_intercept_m is not None:
            raise ValueError("pass either weights or weight_slope/weight_intercept_m, not both")
        w = np.asarray(weights, dtype=float).reshape(-1)
    else:
        w = thesis_weights(
            b,
            1.0 if weight_slope is None else weight_slope,
            2.0 if weight_intercept_m is None else weight_intercept_m,
        )
    x0 = default_init(n, a_idx, a_xy) if init_xy is None else np.asarray(init_xy, dtype=float).reshape(n, 2)
    k, m = a_idx.size, b.size
    ii, jj = pr[:, 0], pr[:, 1]

    def fun(x):
        p = x.reshape(n, 2)
        d = np.hypot(*(p[ii] - p[jj]).T)
        return np.concatenate([(p[a_idx] - a_xy).reshape(-1), w * (b - d)])

    # Jacobian pattern: anchor rows 2a, 2a+1 -> columns 2i, 2i+1; range row 2k+q -> 2I, 2I+1, 2J, 2J+1.
    rows = np.concatenate([np.arange(2 * k), np.repeat(2 * k + np.arange(m), 4)])
    cols = np.concatenate(
        [
            (2 * a_idx[:, None] + np.arange(2)).reshape(-1),
            np.stack([2 * ii, 2 * ii + 1, 2 * jj, 2 * jj + 1], axis=1).reshape(-1),
        ]
    )

    def jac(x):
        p = x.reshape(n, 2)
        diff = p[ii] - p[jj]
        d = np.hypot(*diff.T)
        far = d >= MIN_DIST_M
        u = np.where(far[:, None], diff / np.where(far, d, 1.0)[:, None], [-1.0, 0.0])
        wu = w[:, None] * u
        vals = np.concatenate([np.ones(2 * k), np.concatenate([-wu, wu], axis=1).reshape(-1)])
        jm = sparse.csr_matrix((vals, (rows, cols)), shape=(2 * k + m, 2 * n))
        return jm if sparse_mode else jm.toarray()

    sparse_mode = n > 300 if use_sparse is None else bool(use_sparse)
    loss = _loss(robust_loss, loss_scale, 2 * k)
    f0 = fun(x0.reshape(-1))
    initial_cost = 0.5 * float(np.sum(f0**2 if loss == "linear" else loss(f0**2)[0]))
    t0 = time.perf_counter()
    res = least_squares(
        fun,
        x0.reshape(-1),
        jac=jac,
        method="trf",
        tr_solver="lsmr" if sparse_mode else "exact",
        tr_options={"atol": lsmr_tol, "btol": lsmr_tol} if sparse_mode and lsmr_tol else {},
        loss=loss,
        f_scale=1.0,
        ftol=function_tolerance or None,
        gtol=gradient_tolerance or None,
        xtol=parameter_tolerance or None,
        max_nfev=max_iterations + 1,
    )
    time_s = time.perf_counter() - t0
    return {
        "xy": res.x.reshape(n, 2),
        "cost": float(res.cost),
        "initial_cost": initial_cost,
        "iterations": int(res.nfev - 1),
        "converged": bool(res.status > 0),
        "time_s": time_s,
        "message": res.message,
        "weights": w,
    }


def make_problem(
    n=5000,
    seed=0,
    anchor_every=4,
    step_m=0.7,
    range_sigma_m=0.05,
    near_gap=3,
    n_long_pairs=None,
    long_span=(4, 30),
    turn_sigma_rad=0.5,
):
    """A synthetic walk (the thesis's setting): truth ``xy_gt`` (n, 2) from a heading random walk with
    ``step_m`` steps; anchors every ``anchor_every``-th point (exact, as the thesis simulates them);
    ranges between all points up to ``near_gap`` apart in index (the PDR distances of neighbours), and
    ``n_long_pairs`` (default n // 10) random longer pairs with ``long_span`` index gaps; heading changes
    ``turn_sigma_rad`` per step; range noise ``range_sigma_m * (1 + b / 10 m)``.
    Returns a dict of solve_coordinates' arguments plus ``xy_gt``."""
    rng = np.random.default_rng(seed)
    heading = np.cumsum(rng.normal(0.0, turn_sigma_rad, n))
    steps = step_m * (1.0 + 0.1 * rng.standard_normal(n))[:, None] * np.c_[np.cos(heading), np.sin(heading)]
    xy_gt = np.cumsum(steps, axis=0)
    xy_gt -= xy_gt[0]
    anchors_idx = np.arange(0, n, anchor_every)
    i = np.arange(n)
    pairs = [np.c_[i[:-g], i[g:]] for g in range(1, min(near_gap, n - 1) + 1)]
    n_long = n // 10 if n_long_pairs is None else n_long_pairs
    if n_long > 0 and n > long_span[0] + 1:
        hi = min(long_span[1], n - 1)
        gap = rng.integers(long_span[0], hi + 1, n_long)
        start = rng.integers(0, n - gap)
        pairs.append(np.c_[start, start + gap])
    pairs = np.concatenate(pairs).astype(np.int64)
    true_b = np.hypot(*(xy_gt[pairs[:, 0]] - xy_gt[pairs[:, 1]]).T)
    ranges_m = np.abs(true_b + range_sigma_m * (1.0 + true_b / 10.0) * rng.standard_normal(true_b.size))
    return {
        "n_points": n,
        "anchors_idx": anchors_idx,
        "anchors_xy": xy_gt[anchors_idx],
        "pairs": pairs,
        "ranges_m": ranges_m,
        "xy_gt": xy_gt,
    }
