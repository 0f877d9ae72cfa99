"""Dissimilarity, streaming binning, the bounded fit and the reliability filter (crowd_model)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from stridefix_analyzer.crowd import blocks
from stridefix_analyzer.crowd import model as cm

NAN = np.nan


def test_common_sum_on_hand_made_scans(hand_scans):
    D = cm.dissimilarity(hand_scans, mode="common_sum")
    expected = np.array(
        [[0, 2, NAN, 1], [2, 0, 10, math.sqrt(4 + 25)], [NAN, 10, 0, 5], [1, math.sqrt(29), 5, 0]]
    )
    assert_allclose(D, expected, rtol=0, atol=1e-12, equal_nan=True)


def test_common_scaled_multiplies_by_union_over_common(hand_scans):
    D = cm.dissimilarity(hand_scans, mode="common_scaled")
    # (0,1): common {0}, union {0,1,2}: 2·sqrt(3); (0,3): common {0,1}, union 3: sqrt(1·3/2)
    # (1,2): common {2}, union {0,2}: 10·sqrt(2); (1,3): sqrt(29·3/2); (2,3): 5·sqrt(3)
    assert_allclose(D[0, 1], 2 * math.sqrt(3), atol=1e-12)
    assert_allclose(D[0, 3], math.sqrt(1.5), atol=1e-12)
    assert_allclose(D[1, 2], 10 * math.sqrt(2), atol=1e-12)
    assert_allclose(D[1, 3], math.sqrt(29 * 1.5), atol=1e-12)
    assert_allclose(D[2, 3], 5 * math.sqrt(3), atol=1e-12)
    assert np.isnan(D[0, 2]) and np.isnan(D[2, 0])


def test_unknown_mode_is_rejected(hand_scans):
    with pytest.raises(ValueError, match="not one of"):
        cm.dissimilarity(hand_scans, mode="manhattan")


def test_fingerprint_matrix_keeps_strongest_duplicate_and_nan_for_missing():
    R, bssids = cm.fingerprint_matrix([0, 0, 0, 1], [5, 9, 5, 9], [-70, -60, -65, -80], 3)
    assert_array_equal(bssids, [5, 9])
    assert_allclose(R, [[-65, -60], [NAN, -80], [NAN, NAN]], equal_nan=True)


@pytest.mark.parametrize("block", [1, 3, 7, 64])
def test_pair_blocks_cover_each_pair_once_without_no_common(random_scans, block):
    R, _, _ = random_scans
    seen = {}
    for i0, j0, D, keep in cm.iter_pair_blocks(R, block=block):
        for a, b in zip(*np.nonzero(keep)):
            key = (i0 + a, j0 + b)
            assert key not in seen and key[0] > key[1]
            seen[key] = D[a, b]
    full = cm.dissimilarity(R)
    expected = {(i, j) for i in range(len(R)) for j in range(i) if np.isfinite(full[i, j])}
    assert set(seen) == expected
    assert_allclose([seen[k] for k in sorted(seen)], [full[k] for k in sorted(seen)], atol=1e-12)
    assert (5, 6) not in seen  # scans 5 and 6 share no AP


@pytest.mark.parametrize("mode", cm.MODES)
def test_streaming_binning_equals_brute_force(random_scans, mode):
    R, xy, floor = random_scans
    width = 0.5
    bins = blocks.bin_pairs(R, xy, floor, mode=mode, width_db=width, block=7)
    # brute force: every pair i > j on the same floor with a common AP
    D = cm.dissimilarity(R, mode=mode)
    xs, ds, no_common = [], [], 0
    for i in range(len(R)):
        for j in range(i):
            if floor[i] != floor[j]:
                continue
            if not np.isfinite(D[i, j]):
                no_common += 1
                continue
            xs.append(D[i, j])
            ds.append(math.dist(xy[i], xy[j]))
    xs, ds = np.array(xs), np.array(ds)
    k = (xs / width).astype(int)
    n = len(bins.count)
    assert bins.n_pairs == len(xs) and bins.n_no_common == no_common > 0
    assert_array_equal(bins.count, np.bincount(k, minlength=n))
    assert_allclose(bins.sum_x, np.bincount(k, weights=xs, minlength=n), rtol=1e-12, atol=1e-9)
    assert_allclose(bins.sum_d, np.bincount(k, weights=ds, minlength=n), rtol=1e-12, atol=1e-9)
    assert_allclose(bins.sum_d2, np.bincount(k, weights=ds**2, minlength=n), rtol=1e-12, atol=1e-9)
    assert bins.min_d == pytest.approx(ds.min())
    coarse = bins.coarsen(4)
    assert coarse.count.sum() == len(xs)
    assert_allclose(coarse.sum_d.sum(), ds.sum(), rtol=1e-12)


def _synthetic_pairs(X, n=20000, noise=1.0, seed=3):
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 80, n)
    d = np.maximum(X[0], X[1] + X[2] * x) + rng.normal(0, noise, n)
    return x, np.abs(d) + 0.3


def test_bounded_fit_recovers_known_parameters():
    X = (2.0, -3.0, 0.4)
    x, d = _synthetic_pairs(X, noise=0.5)
    m = cm.fit_distance_model(x, d - 0.3, min_distance_m=2.5)
    assert_allclose(m.params, X, atol=0.08)
    assert m.r2 > 0.95 and m.rmse_m == pytest.approx(0.5, abs=0.05)


def test_binned_fit_matches_pair_fit():
    X = (1.0, -2.0, 0.3)
    x, d = _synthetic_pairs(X, noise=1.0)
    pair = cm.fit_distance_model(x, d)
    bins = cm.PairBins(width=0.25)
    for s in range(0, len(x), 3000):  # streamed in blocks
        bins.add(x[s : s + 3000], d[s : s + 3000])
    binned = cm.fit_binned(bins)
    assert_allclose(binned.params, pair.params, atol=0.02)
    assert binned.rmse_m == pytest.approx(pair.rmse_m, rel=0.01)
    assert binned.r2 == pytest.approx(pair.r2, abs=0.005)
    assert "exact streaming binning" in binned.method


def test_fit_respects_bounds():
    # data whose best line has a positive intercept and a floor above the smallest distance
    rng = np.random.default_rng(1)
    x = rng.uniform(0, 50, 5000)
    d = 5.0 + 0.2 * x + rng.normal(0, 0.2, 5000)
    m = cm.fit_distance_model(x, d, min_distance_m=1.0)
    assert 0.0 <= m.floor_m <= 1.0 + 1e-12
    assert m.intercept_m <= 0.0
    assert m.slope_m_per_db >= 0.0
    # a decreasing relation cannot give a negative slope
    m2 = cm.fit_distance_model(x, 30.0 - 0.3 * x)
    assert m2.slope_m_per_db >= 0.0 and m2.intercept_m <= 0.0


def test_model_json_round_trip():
    m = cm.DistanceModel(1.0, -2.0, 0.3, mode="common_scaled", rmse_m=3.0, r2=0.5)
    back = cm.DistanceModel.from_json(m.to_json())
    assert back.params == m.params and back.mode == "common_scaled"
    with pytest.raises(ValueError, match="lacks"):
        cm.DistanceModel.from_json({"floor_m": 1})


def test_reliability_filter_keeps_model_distance_up_to_tau_max():
    g = np.array([0.0, 4.0, 4.5, 4.6, 10.0, NAN])
    keep, thr = cm.reliability_mask(g, tau=0.45)
    assert thr == pytest.approx(4.5)
    assert_array_equal(keep, [True, True, True, False, False, False])
    with pytest.raises(ValueError):
        cm.reliability_mask(g, tau=0.0)


def test_model_distance_is_floored_linear():
    assert_allclose(
        cm.model_distance([0, 10, 20, NAN], (2.0, -1.0, 0.25)), [2.0, 2.0, 4.0, NAN], equal_nan=True
    )


def test_min_common_aps_excludes_pairs_sharing_fewer(hand_scans):
    D = cm.dissimilarity(hand_scans)  # thesis: one common AP is enough
    bins1 = blocks.bin_pairs(hand_scans, np.zeros((4, 2)))
    bins2 = blocks.bin_pairs(hand_scans, np.zeros((4, 2)), min_common=2)
    assert bins1.n_pairs == int(np.sum(np.isfinite(D[np.tril_indices(4, -1)])))
    # only (0,3) and (1,3) share two APs
    assert bins2.n_pairs == 2 and bins2.n_no_common == 4
