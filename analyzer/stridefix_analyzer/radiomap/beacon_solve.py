"""Every beacon's position at once, given the site's log-distance model: a numpy-batched, bounded
Levenberg–Marquardt over all beacons (:func:`solve_positions`).

Beacon g's problem (:mod:`.beacons`): minimise over p_g in the box [lo_g, hi_g]

    F_g(p) = Σ_{i in g} f_i(p)²,   f_i(p) = r_i − A + 10·n·log10(max(|q_i − p|, MIN_RANGE_M)),

q_i the reading's placed position, r_i its RSSI. The beacons' problems are independent 2-D least
squares, so one pass over the readings (np.bincount by beacon) gives every beacon's Gauss–Newton
normal equations JᵀJ·δ = −Jᵀf; with ∂f_i/∂p = c·(p − q_i)/d_i², c = 10·n/ln 10 (0 within
MIN_RANGE_M, where f_i is flat). Each beacon keeps its own Marquardt damping λ (a step is taken when
it lowers F_g, else λ grows), and a coordinate on its bound whose descent leaves the box is held
(projected LM, Kanzow, Yamashita & Fukushima 2004). A beacon stops when its step is below
:data:`XTOL_M` or its relative cost change below :data:`FTOL`; all stop after :data:`MAX_ITER`.

This is the same local minimiser as one scipy ``least_squares`` (TRF) call per beacon from the same
start (tests/python/sitefile/test_beacon_solve.py checks it against scipy), at the cost of one
numpy pass per iteration instead of a Python-level solver per beacon.

Cost: O(R) per iteration for R readings (about 12 passes over them), ≤ MAX_ITER iterations; memory
O(R + G) for G beacons.
"""

from __future__ import annotations

import math

import numpy as np

#: The model's reference distance [m]: a reading closer than this is taken at this range.
MIN_RANGE_M = 1.0
#: A beacon has converged when its accepted step is below this [m] (1 µm: far below the 1 cm the
#: positions are compared at) or its cost falls by less than FTOL relative.
XTOL_M = 1e-6
FTOL = 1e-12
#: Iteration cap (LM on these 2-D problems converges in well under 50 from the centroid start).
MAX_ITER = 200
#: Marquardt damping: start, and the factors on a rejected / accepted step.
LAMBDA_START = 1e-3
LAMBDA_UP, LAMBDA_DOWN = 10.0, 0.3
LAMBDA_MAX = 1e12
#: Gauss–Newton (JᵀJ) steps before Newton steps (the full Hessian) are used: Gauss–Newton's first
#: steps are long, as scipy's trust-region steps are, and find the same basin; Newton converges fast
#: inside it (these residuals are large: Gauss–Newton alone creeps along a valley).
GN_ITER = 5


def _evaluate(
    g: np.ndarray, qx: np.ndarray, qy: np.ndarray, r: np.ndarray, a: float, n: float, p: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """At positions ``p`` (G × 2): residuals f_i, u_i = p − q_i (x, y), k_i = c/d_i² (0 within
    MIN_RANGE_M) and the per-beacon costs Σ f²."""
    dx, dy = p[g, 0] - qx, p[g, 1] - qy
    d = np.hypot(dx, dy)
    far = d > MIN_RANGE_M
    f = r - a + 10.0 * n * np.log10(np.maximum(d, MIN_RANGE_M))
    k = np.where(far, 10.0 * n / math.log(10.0) / np.where(far, d * d, 1.0), 0.0)
    return f, dx, dy, k, np.bincount(g, f * f, minlength=len(p))


def _newton(g: np.ndarray, ev: tuple[np.ndarray, ...], c: float, n_g: int) -> tuple[np.ndarray, ...]:
    """Per beacon JᵀJ (xx, xy, yy), the Hessian Σ(∇f∇fᵀ + f·∇²f) (xx, xy, yy) and Jᵀf (x, y), with
    ∇f = k·u and ∇²f = k·I − 2·k²/c·u·uᵀ."""
    f, dx, dy, k, _ = ev
    jx, jy = k * dx, k * dy
    w = f / c
    sums = [
        np.bincount(g, v, minlength=n_g)
        for v in (jx * jx, jx * jy, jy * jy, f * k, w * jx * jx, w * jx * jy, w * jy * jy, jx * f, jy * f)
    ]
    sxx, sxy, syy, fk, wxx, wxy, wyy, bx, by = sums
    return sxx, sxy, syy, sxx + fk - 2.0 * wxx, sxy - 2.0 * wxy, syy + fk - 2.0 * wyy, bx, by


def solve_positions(
    g: np.ndarray,
    qx: np.ndarray,
    qy: np.ndarray,
    r: np.ndarray,
    a: float,
    n: float,
    start: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
) -> np.ndarray:
    """Every beacon's bounded least-squares position (see the module docstring).

    Parameters
    ----------
    g : (R,) int
        The reading's beacon, 0 … G−1.
    qx, qy : (R,) float
        The reading's placed position [m].
    r : (R,) float
        Its RSSI [dBm].
    a, n : float
        The model: RSSI at 1 m [dBm] and path-loss exponent.
    start, lo, hi : (G, 2) float
        Start positions and the box per beacon [m] (start is clipped into the box).

    Returns
    -------
    (G, 2) float
        The positions [m].
    """
    c = 10.0 * n / math.log(10.0)
    out = np.clip(np.asarray(start, np.float64), lo, hi)
    beacons = np.arange(len(out))  # the beacons still iterated, and their readings below
    p, lo, hi = out.copy(), np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    ev = _evaluate(g, qx, qy, r, a, n, p)
    lam = np.full(len(p), LAMBDA_START)
    live = np.ones(len(p), dtype=bool)
    for it in range(MAX_ITER):
        if not live.any():
            break
        if 2 * live.sum() < len(live):  # drop the converged beacons' readings from the passes
            out[beacons] = p
            rows = live[g]
            g = (np.cumsum(live) - 1)[g[rows]]
            qx, qy, r = qx[rows], qy[rows], r[rows]
            ev = (ev[0][rows], ev[1][rows], ev[2][rows], ev[3][rows], ev[4][live])
            beacons, p, lo, hi, lam = beacons[live], p[live], lo[live], hi[live], lam[live]
            live = live[live]
        n_g = len(p)
        sxx, sxy, syy, hxx, hxy, hyy, bx, by = _newton(g, ev, c, n_g)
        # Newton where the Hessian is positive definite (after GN_ITER steps), else Gauss–Newton
        pd = (hxx > 0) & (hxx * hyy - hxy * hxy > 0) & (it >= GN_ITER)
        hxx, hxy, hyy = np.where(pd, hxx, sxx), np.where(pd, hxy, sxy), np.where(pd, hyy, syy)
        # a coordinate on its bound whose descent direction (−b) leaves the box is held
        hold_x = ((p[:, 0] <= lo[:, 0]) & (bx > 0)) | ((p[:, 0] >= hi[:, 0]) & (bx < 0))
        hold_y = ((p[:, 1] <= lo[:, 1]) & (by > 0)) | ((p[:, 1] >= hi[:, 1]) & (by < 0))
        bx, by = np.where(hold_x, 0.0, bx), np.where(hold_y, 0.0, by)
        hxy = np.where(hold_x | hold_y, 0.0, hxy)
        mxx = hxx + lam * np.maximum(sxx, 1e-12) + hold_x
        myy = hyy + lam * np.maximum(syy, 1e-12) + hold_y
        det = mxx * myy - hxy * hxy
        step = np.column_stack([(-bx * myy + by * hxy) / det, (-by * mxx + bx * hxy) / det])
        step[~live] = 0.0
        trial = np.clip(p + step, lo, hi)
        ev1 = _evaluate(g, qx, qy, r, a, n, trial)
        cost, cost1 = ev[4], ev1[4]
        take = live & (cost1 <= cost)
        moved = np.hypot(*(trial - p).T)
        small = take & ((moved < XTOL_M) | (cost - cost1 <= FTOL * cost))
        lam = np.where(live, np.where(take, lam * LAMBDA_DOWN, lam * LAMBDA_UP), lam)
        live &= ~small & (lam < LAMBDA_MAX)
        p = np.where(take[:, None], trial, p)
        t = take[g]
        f, ux, uy, k = (np.where(t, v1, v0) for v1, v0 in zip(ev1[:4], ev[:4]))
        ev = (f, ux, uy, k, np.where(take, cost1, cost))
    out[beacons] = p
    return out
