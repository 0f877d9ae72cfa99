"""The batched beacon solver (radiomap/beacon_solve.py) against scipy's least_squares, one call per
beacon, on synthetic beacons heard from all around. The cost is not smooth (a reading's term is flat
within MIN_RANGE_M of it) and has local minima near readings, so two local methods from the same
start can end in different ones: most beacons agree within 1 cm, and the batched solver's total cost
is no higher than scipy's."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares
from stridefix_analyzer.radiomap.beacon_solve import MIN_RANGE_M, solve_positions

A_DBM, N_EXP, SIGMA_DB = -62.0, 1.9, 5.0


def _beacons(seed: int, n_beacons: int = 40):
    """Beacons on a 60 m square, each heard at 30..120 random spots within 25 m of it."""
    rng = np.random.default_rng(seed)
    true = rng.uniform(0.0, 60.0, size=(n_beacons, 2))
    counts = rng.integers(30, 120, size=n_beacons)
    g = np.repeat(np.arange(n_beacons), counts)
    ang, rad = rng.uniform(0, 2 * np.pi, len(g)), rng.uniform(2.0, 25.0, len(g))
    qx, qy = true[g, 0] + rad * np.cos(ang), true[g, 1] + rad * np.sin(ang)
    d = np.maximum(np.hypot(qx - true[g, 0], qy - true[g, 1]), MIN_RANGE_M)
    r = A_DBM - 10 * N_EXP * np.log10(d) + rng.normal(0, SIGMA_DB, len(g))
    start = true + rng.normal(0, 3.0, true.shape)
    lo = (
        np.column_stack(
            [
                np.minimum.reduceat(qx, np.r_[0, np.cumsum(counts)[:-1]]),
                np.minimum.reduceat(qy, np.r_[0, np.cumsum(counts)[:-1]]),
            ]
        )
        - 10
    )
    hi = (
        np.column_stack(
            [
                np.maximum.reduceat(qx, np.r_[0, np.cumsum(counts)[:-1]]),
                np.maximum.reduceat(qy, np.r_[0, np.cumsum(counts)[:-1]]),
            ]
        )
        + 10
    )
    return g, qx, qy, r, start, lo, hi, true


def _cost(x, y, r, p):
    return np.sum(
        (r - (A_DBM - 10 * N_EXP * np.log10(np.maximum(np.hypot(x - p[0], y - p[1]), MIN_RANGE_M)))) ** 2
    )


def _scipy(x, y, r, start, lo, hi):
    """The reference: one scipy least_squares (TRF) call for one beacon, as learn_beacons did."""

    def resid(q):
        return r - (A_DBM - 10 * N_EXP * np.log10(np.maximum(np.hypot(x - q[0], y - q[1]), MIN_RANGE_M)))

    return least_squares(resid, start, bounds=(lo, hi)).x


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_same_minimum_as_scipy_per_beacon(seed):
    g, qx, qy, r, start, lo, hi, true = _beacons(seed)
    p = solve_positions(g, qx, qy, r, A_DBM, N_EXP, start, lo, hi)
    dist, cost, cost_ref = [], 0.0, 0.0
    for b in range(len(start)):
        s = g == b
        x, y, rr = qx[s], qy[s], r[s]
        ref = _scipy(x, y, rr, start[b], lo[b], hi[b])
        dist.append(np.hypot(*(p[b] - ref)))
        cost, cost_ref = cost + _cost(x, y, rr, p[b]), cost_ref + _cost(x, y, rr, ref)
    assert np.mean(np.array(dist) < 0.01) >= 0.9, np.round(dist, 3)
    assert cost <= cost_ref * (1 + 1e-3), (cost, cost_ref)
    # and the fit is the truth within the noise (5 dB σ, ≥ 30 readings from 2..25 m)
    assert np.median(np.hypot(*(p - true).T)) < 2.0


def test_bounds_hold_and_start_outside_is_clipped():
    g, qx, qy, r, start, lo, hi, _ = _beacons(4, n_beacons=5)
    hi = lo + 3.0  # every box far too small: the minimum is on its edge
    p = solve_positions(g, qx, qy, r, A_DBM, N_EXP, start + 100.0, lo, hi)
    assert np.all(p >= lo) and np.all(p <= hi)
    for b in range(5):
        s = g == b
        ref = _scipy(qx[s], qy[s], r[s], np.clip(start[b] + 100.0, lo[b] + 1e-6, hi[b] - 1e-6), lo[b], hi[b])
        assert np.hypot(*(p[b] - ref)) < 0.01, (b, p[b], ref)
