"""The native Kannan coordinate solver (analyzer/native, ``stridefix_native``, C++/Ceres) against the
thesis's 1-D check and against its scipy twin (``stridefix_native_reference``). Nothing is skipped: the
module is built by ``make build`` (CMake) and put on the venv's path by tools/deps.sh.

Tolerances: the 1-D check is exact to 1e-9 m; Ceres and scipy agree to 1e-6 m when both run to tight
tolerances (1e-15) from the same start.
"""

from __future__ import annotations

import numpy as np
import pytest
import stridefix_native as sn
import stridefix_native_reference as ref
from numpy.testing import assert_allclose

TIGHT = {
    "function_tolerance": 1e-15,
    "gradient_tolerance": 1e-15,
    "parameter_tolerance": 1e-15,
    "max_iterations": 500,
}
# The reference with a dense Jacobian and exact trust-region steps: with a robust loss, scipy's LSMR
# steps can stall where the rescaled Jacobian (rows in Huber's linear part) is nearly singular.
REF = {"use_sparse": False}


def _cloud(n, seed, n_anchors=4, range_sigma_m=0.05, init_sigma_m=0.3, k_near=6):
    """A well-posed random problem: n points uniform in a 20 m square, ``n_anchors`` of them anchored,
    ranges from each point to its ``k_near`` nearest (noise ``range_sigma_m``), and a start
    ``init_sigma_m`` off the truth. (Walks are a poor cross-check: on straight stretches a free point's
    cross-track position is only second-order observable, so the minimum is flat and not unique.)"""
    rng = np.random.default_rng(seed)
    xy_gt = rng.uniform(0.0, 20.0, (n, 2))
    anchors = rng.choice(n, n_anchors, replace=False)
    d = np.linalg.norm(xy_gt[:, None] - xy_gt[None], axis=2)
    near = np.argsort(d, axis=1)[:, 1 : k_near + 1]
    pairs = np.unique(np.sort(np.c_[np.repeat(np.arange(n), k_near), near.ravel()], axis=1), axis=0)
    ranges = np.abs(d[pairs[:, 0], pairs[:, 1]] + range_sigma_m * rng.standard_normal(len(pairs)))
    pb = {
        "n_points": n,
        "anchors_idx": anchors,
        "anchors_xy": xy_gt[anchors],
        "pairs": pairs,
        "ranges_m": ranges,
        "init_xy": xy_gt + rng.normal(0.0, init_sigma_m, xy_gt.shape),
    }
    return pb, xy_gt


def _thesis_1d():
    """Thesis §3.1.4: true positions 1..5 on a line, the first known, unit ranges between neighbours."""
    return {
        "n_points": 5,
        "anchors_idx": [0],
        "anchors_xy": [[1.0, 0.0]],
        "pairs": [[0, 1], [1, 2], [2, 3], [3, 4]],
        "ranges_m": [1.0, 1.0, 1.0, 1.0],
    }


# --- the thesis's 1-D check -------------------------------------------------------------------------


@pytest.mark.parametrize("init", ["default", "line"])
@pytest.mark.parametrize("weighting", ["thesis", "unit"])
def test_thesis_1d_check_comes_back_exact(init, weighting):
    pb = _thesis_1d()
    init_xy = None if init == "default" else np.c_[1.0 + 0.7 * np.arange(5), np.zeros(5)]
    weights = None if weighting == "thesis" else np.ones(4)
    out = sn.solve_coordinates(**pb, weights=weights, init_xy=init_xy)
    assert out["converged"], out["message"]
    assert_allclose(out["xy"], np.c_[np.arange(1.0, 6.0), np.zeros(5)], rtol=0, atol=1e-9)
    assert out["cost"] < 1e-20


def test_thesis_1d_check_scipy_reference_agrees():
    out = ref.solve_coordinates_ref(**_thesis_1d(), use_sparse=False, **TIGHT)
    assert_allclose(out["xy"], np.c_[np.arange(1.0, 6.0), np.zeros(5)], rtol=0, atol=1e-9)


def test_non_monotone_1d_path_with_all_pairs():
    """Thesis note: for the path 1, 2, 1, 2, 1 every pairwise |x_i - x_j| is needed (zero ranges included)."""
    x_gt = np.array([1.0, 2.0, 1.0, 2.0, 1.0])
    i, j = np.triu_indices(5, k=1)
    out = sn.solve_coordinates(
        5,
        [0],
        [[1.0, 0.0]],
        np.c_[i, j],
        np.abs(x_gt[i] - x_gt[j]),
        init_xy=np.c_[x_gt + 0.1 * np.array([0, 1, -1, 1, -1]), np.zeros(5)],
        **TIGHT,
    )
    assert_allclose(out["xy"], np.c_[x_gt, np.zeros(5)], rtol=0, atol=1e-7)


# --- Ceres equals scipy -----------------------------------------------------------------------------


@pytest.mark.parametrize("n, seed", [(20, 1), (30, 2), (40, 3), (50, 4), (50, 5)])
@pytest.mark.parametrize("robust_loss", ["none", "huber", "cauchy"])
def test_ceres_equals_scipy_on_small_noisy_problems(n, seed, robust_loss):
    # Cauchy is not convex: from a start further off, the two minimisers may settle in different basins.
    pb, _ = _cloud(n, seed, init_sigma_m=0.1 if robust_loss == "cauchy" else 0.3)
    kw = {"robust_loss": robust_loss, "loss_scale": 0.1, **TIGHT}
    ceres = sn.solve_coordinates(**pb, **kw)
    scipy = ref.solve_coordinates_ref(**pb, **REF, **kw)
    assert ceres["converged"], ceres["message"]
    assert scipy["converged"], scipy["message"]
    assert_allclose(ceres["xy"], scipy["xy"], rtol=0, atol=1e-6)
    assert_allclose(ceres["cost"], scipy["cost"], rtol=1e-9, atol=1e-15)
    assert ceres["cost"] < ceres["initial_cost"]


def test_ceres_equals_scipy_dense_and_sparse_reference():
    """The reference's two trust-region solvers (exact/dense, LSMR/sparse) reach the same point as Ceres."""
    pb, _ = _cloud(40, 7)
    ceres = sn.solve_coordinates(**pb, **TIGHT)
    for use_sparse in (False, True):
        scipy = ref.solve_coordinates_ref(**pb, use_sparse=use_sparse, lsmr_tol=1e-14, **TIGHT)
        assert_allclose(ceres["xy"], scipy["xy"], rtol=0, atol=1e-6)


def test_ceres_equals_scipy_from_the_default_start():
    """Same start computed on each side (C++ default_init vs numpy interpolation): a noise-free walk."""
    pb = ref.make_problem(n=40, seed=3, anchor_every=4, range_sigma_m=0.0, turn_sigma_rad=0.6)
    pb.pop("xy_gt")
    ceres = sn.solve_coordinates(**pb, **TIGHT)
    scipy = ref.solve_coordinates_ref(**pb, **REF, **TIGHT)
    assert_allclose(ceres["xy"], scipy["xy"], rtol=0, atol=1e-6)


def test_default_start_equals_reference_interpolation():
    """Anchors unsorted, one point anchored twice (mean), free points interpolated, held beyond the ends."""
    idx = np.array([7, 3, 12, 3])
    a_xy = np.array([[10.0, -2.0], [2.0, 4.0], [0.0, 0.0], [4.0, 6.0]])
    got = sn.default_init(16, idx, a_xy)
    assert_allclose(got, ref.default_init(16, idx, a_xy), rtol=0, atol=1e-12)
    assert_allclose(got[3], [3.0, 5.0])
    assert_allclose(got[5], [6.5, 1.5])  # halfway between 3 and 7
    assert_allclose(got[:3], np.tile([3.0, 5.0], (3, 1)))  # held before the first anchor
    assert_allclose(got[13:], np.zeros((3, 2)))  # held after the last
    out = sn.solve_coordinates(16, idx, a_xy, [[0, 1]], [1.0], max_iterations=0)
    assert_allclose(out["xy"], got, rtol=0, atol=0)


def test_coincident_start_points_are_pushed_apart():
    """Past the last anchor the default start puts every point on it (|p_I - p_J| = 0): not stuck."""
    x_gt = np.arange(10.0)
    pairs = np.c_[np.arange(9), np.arange(1, 10)]
    out = sn.solve_coordinates(10, [0, 2], [[0.0, 0.0], [2.0, 0.0]], pairs, np.ones(9), **TIGHT)
    assert_allclose(out["xy"], np.c_[x_gt, np.zeros(10)], rtol=0, atol=1e-9)


# --- weights ----------------------------------------------------------------------------------------


def test_thesis_weight_law_equals_explicit_weights():
    pb, _ = _cloud(40, 11)
    b = pb["ranges_m"]
    law = sn.solve_coordinates(**pb, weight_slope=1.0, weight_intercept_m=2.0, **TIGHT)
    default = sn.solve_coordinates(**pb, **TIGHT)
    explicit = sn.solve_coordinates(**pb, weights=1.0 / (1.0 * b + 2.0), **TIGHT)
    assert_allclose(law["weights"], 1.0 / (b + 2.0), rtol=1e-15)
    assert_allclose(sn.thesis_weights(b, 3.0, 2.0), 1.0 / (3.0 * b + 2.0), rtol=1e-15)
    assert_allclose(law["xy"], explicit["xy"], rtol=0, atol=1e-12)
    assert_allclose(default["xy"], explicit["xy"], rtol=0, atol=1e-12)
    # ... and the weights matter: unit weights or another law give another solution.
    unit = sn.solve_coordinates(**pb, weights=np.ones_like(b), **TIGHT)
    steep = sn.solve_coordinates(**pb, weight_slope=10.0, weight_intercept_m=0.5, **TIGHT)
    assert np.max(np.abs(unit["xy"] - law["xy"])) > 1e-3
    assert np.max(np.abs(steep["xy"] - law["xy"])) > 1e-3
    # the cost is 1/2 sum of squared weighted residuals
    p = explicit["xy"]
    r_range = (b - np.linalg.norm(p[pb["pairs"][:, 0]] - p[pb["pairs"][:, 1]], axis=1)) / (b + 2.0)
    r_anchor = p[pb["anchors_idx"]] - pb["anchors_xy"]
    assert_allclose(explicit["cost"], 0.5 * (np.sum(r_range**2) + np.sum(r_anchor**2)), rtol=1e-9)


def test_weight_law_must_stay_positive():
    with pytest.raises(ValueError, match="c > -m"):
        sn.solve_coordinates(**_thesis_1d(), weight_intercept_m=-1.0)
    with pytest.raises(ValueError, match="either weights or"):
        sn.solve_coordinates(**_thesis_1d(), weights=np.ones(4), weight_slope=1.0)


# --- robust loss ------------------------------------------------------------------------------------


@pytest.mark.parametrize("robust_loss", ["huber", "cauchy"])
def test_robust_loss_reduces_an_outlier_range(robust_loss):
    """GIVEN a clean problem WHEN one range is 5 m too long THEN the plain solution is pulled apart
    there, and a robust loss leaves the outlier largely unexplained and the points closer to the truth."""
    pb, xy_gt = _cloud(40, 5, range_sigma_m=0.0)
    i, j = pb["pairs"][10]
    pb["ranges_m"] = pb["ranges_m"].copy()
    pb["ranges_m"][10] += 5.0
    plain = sn.solve_coordinates(**pb, **TIGHT)
    robust = sn.solve_coordinates(**pb, robust_loss=robust_loss, loss_scale=0.05, **TIGHT)
    assert np.max(np.abs(plain["xy"] - robust["xy"])) > 0.05  # the loss changes the result

    def err(xy):
        return np.max(np.linalg.norm(xy - xy_gt, axis=1))

    def fitted(xy):
        return np.linalg.norm(xy[i] - xy[j])

    assert err(robust["xy"]) < 0.2 * err(plain["xy"])
    # the outlier's influence: how far the fitted distance moved towards the outlier value
    true_d = np.linalg.norm(xy_gt[i] - xy_gt[j])
    assert abs(fitted(robust["xy"]) - true_d) < 0.2 * abs(fitted(plain["xy"]) - true_d)
    # scipy, with the same loss on the range rows, agrees
    scipy = ref.solve_coordinates_ref(**pb, robust_loss=robust_loss, loss_scale=0.05, **REF, **TIGHT)
    assert_allclose(robust["xy"], scipy["xy"], rtol=0, atol=1e-6)


# --- bad input --------------------------------------------------------------------------------------


def test_bad_input_lists_every_problem():
    with pytest.raises(ValueError) as exc:
        sn.solve_coordinates(
            4, [0, 9], [[0.0, 0.0], [1.0, 1.0]], [[0, 1], [2, 2], [3, 7]], [1.0, -1.0, np.nan]
        )
    msg = str(exc.value)
    for part in ("anchor index", "pair index", "itself", "negative or non-finite"):
        assert part in msg, msg


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"anchors_idx": [0.5]}, "integers"),
        ({"anchors_xy": [[1.0, 0.0, 0.0]]}, "shape"),
        ({"pairs": [0, 1, 1, 2, 2, 3, 3, 4]}, "shape"),
        ({"init_xy": np.zeros((4, 2))}, "init_xy"),
        ({"anchors_idx": [], "anchors_xy": np.zeros((0, 2))}, "default start needs at least one anchor"),
    ],
)
def test_bad_shapes_and_types(kwargs, match):
    pb = {**_thesis_1d(), **kwargs}
    with pytest.raises(ValueError, match=match):
        sn.solve_coordinates(**pb)


def test_bad_loss_name():
    with pytest.raises(ValueError, match="robust_loss"):
        sn.solve_coordinates(**_thesis_1d(), robust_loss="tukey")


# --- timing harness ---------------------------------------------------------------------------------


def test_benchmark_harness_runs():
    """The timing harness of `stridefix-lab bench native-solver` (its numbers are for reading, not asserted). Its walk's minimum is flat
    (straight stretches), so the two solvers need not meet to 1e-6 there (see _cloud); both must lower
    the cost from the same start to nearly the same value."""
    from stridefix_lab.bench.native_solver import benchmark

    out = benchmark(n=300, seed=1, max_iterations=100)
    assert out["n_points"] == 300 and out["n_anchors"] == 75
    assert out["ceres_s"] > 0 and out["scipy_s"] > 0 and np.isfinite(out["max_diff_m"])
    assert out["ceres_cost"] < 0.5 * out["initial_cost"] and out["scipy_cost"] < 0.5 * out["initial_cost"]
    assert_allclose(out["ceres_cost"], out["scipy_cost"], rtol=0.05)
