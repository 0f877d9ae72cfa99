"""realbench's measurements for the ekf scheme: the fix-error model (fixmodel) and the start priors
(priors), on synthetic residuals whose answer is known."""

from __future__ import annotations

import math

import numpy as np
import pytest
from stridefix_lab.realbench import fixmodel, priors


def _ar_walk(
    rng: np.random.Generator, n: int, step_m: float, sigma_c: float, length_m: float, sigma_w: float
):
    """Fix errors of one walk: a Gauss–Markov part (σ_c, decorrelating over length_m walked) plus white
    noise σ_w, accuracy 2 m, one fix every step_m metres; rows as fix_residuals_m gives them."""
    phi = math.exp(-step_m / length_m)
    c = rng.normal(0.0, sigma_c, 2)
    rows = []
    for k in range(n):
        c = phi * c + rng.normal(0.0, sigma_c * math.sqrt(1 - phi * phi), 2)
        e = c + rng.normal(0.0, sigma_w, 2)
        rows.append((e[0], e[1], 2.0, k * step_m))
    return np.array(rows)


def test_model_recovers_a_known_correlated_error():
    rng = np.random.default_rng(7)
    walks = [_ar_walk(rng, 60, 1.5, 3.0, 15.0, 1.5) for _ in range(80)]
    m = fixmodel.model_of(walks)
    assert m is not None and m["fixes"] == 4800
    # one fix's variance per axis is 3² + 1.5² = 11.25 m², i.e. M = 11.25 / 2² = 2.81 (winsorised: less)
    assert 2.0 < m["m_xx"] < 2.9 and 2.0 < m["m_yy"] < 2.9
    assert abs(m["m_xy"]) < 0.2
    assert 2.4 < m["correlated_sigma_m"] < 3.3
    assert 0.7 < m["correlated_share"] < 0.9  # 3² / (3² + 1.5²) = 0.8
    assert 8.0 < m["correlation_length_m"] < 25.0
    f = m["site_fields"]  # what the fold's site file carries
    assert f["has_fix_model"] and f["fix_cov_per_acc2"] == [m["m_xx"], m["m_xy"], m["m_yy"]]
    assert f["fix_bias_sigma_m"] == m["correlated_sigma_m"]
    assert f["fix_white_share"] == pytest.approx(1.0 - m["correlated_share"])
    from stridefix_analyzer.io import sitefile

    sitefile.validate_site(sitefile.new_site(**f))  # a valid site_t


def test_independent_fixes_have_no_correlated_part():
    rng = np.random.default_rng(3)
    walks = [
        np.column_stack([rng.normal(0, 2.0, (50, 2)), np.full(50, 2.0), np.arange(50) * 1.5])
        for _ in range(40)
    ]
    m = fixmodel.model_of(walks)
    assert m is not None
    assert m["correlated_sigma_m"] < 0.6  # noise: no bin's covariance is really positive
    assert 0.7 < m["m_xx"] < 1.1  # σ 2 m at accuracy 2 m, winsorised


def test_too_few_fixes_give_no_model():
    assert fixmodel.model_of([np.zeros((5, 4))]) is None


def test_start_priors_from_the_walks_spread():
    # per-walk heading offsets 0, ±0.1 rad: circular σ ≈ 0.082 rad; K 0.40, 0.44, 0.36: 10 % relative σ
    rot = [
        {"sum_cos": 10 * math.cos(a), "sum_sin": 10 * math.sin(a), "n_steps": 10, "n_segments": 1}
        for a in (0.0, 0.1, -0.1, 0.5)
    ]
    seg_walk = np.array([0, 1, 2, 3])
    true_m = np.array([40.0, 44.0, 36.0, 10.0])
    weinberg = np.array([100.0, 100.0, 100.0, 100.0])
    out = priors.ekf_start_priors(rot, seg_walk, true_m, weinberg, exclude=3)
    assert out["ekf.init_bias_sigma_rad"] == pytest.approx(
        math.sqrt(-2 * math.log((1 + 2 * math.cos(0.1)) / 3))
    )
    assert out["ekf.init_scale_sigma"] == pytest.approx(0.1)
    # two training walks are too few: the firmware's defaults stay
    assert priors.ekf_start_priors(rot[:3], seg_walk[:3], true_m[:3], weinberg[:3], exclude=0) == {}


def test_bias_random_walk_from_segment_offsets():
    # offsets change by ±0.1 rad between segments 10 m apart: 0.01 rad² per 10 m = 0.001 rad²/m
    segs = [[(10.0 * k, 0.1 * (k % 2)) for k in range(6)] for _ in range(3)]
    rot = [{"sum_cos": 1.0, "sum_sin": 0.0, "n_steps": 5, "n_segments": 6, "segments": s} for s in segs]
    assert priors.bias_rw_rad2_per_m(rot, exclude=0) == pytest.approx(0.001)
    assert math.isnan(priors.bias_rw_rad2_per_m(rot[:1], exclude=0))  # no other walk


def test_variance_law_separates_floor_and_accuracy_part():
    rng = np.random.default_rng(11)
    acc = rng.uniform(1.5, 6.0, 20000)
    e = rng.normal(0.0, np.sqrt(9.0 + 0.5 * acc**2))  # F = 9 m², M = 0.5
    f, m = fixmodel.variance_law(e**2, acc**2)
    assert f == pytest.approx(9.0, rel=0.1) and m == pytest.approx(0.5, rel=0.1)
    # an error that ignores the accuracy is all floor
    f, m = fixmodel.variance_law(rng.normal(0.0, 3.0, 20000) ** 2, acc**2)
    assert f == pytest.approx(9.0, rel=0.1) and m == fixmodel.MIN_PER_ACC2 or m < 0.05


def test_model_sets_give_the_firmware_the_site_fields_numbers():
    """The --set form of a measured model (for inner-CV replays on sites without it): every ekf.fix_*
    key once, each with the number the site field holds."""
    fields = {
        "has_fix_model": True,
        "fix_floor_cov_m2": [1.5, 0.25, 2.5],
        "fix_cov_per_acc2": [0.5, -0.125, 0.75],
        "fix_bias_sigma_m": 1.25,
        "fix_bias_length_m": 12.0,
        "fix_white_share": 0.625,
    }
    sets = dict(kv.split("=") for kv in fixmodel.model_sets(fields))
    assert list(sets) == list(fixmodel.KEYS)
    assert {k: float(v) for k, v in sets.items()} == {
        "ekf.fix_var_x_per_acc2": 0.5,
        "ekf.fix_var_y_per_acc2": 0.75,
        "ekf.fix_cov_xy_per_acc2": -0.125,
        "ekf.fix_floor_xx_m2": 1.5,
        "ekf.fix_floor_yy_m2": 2.5,
        "ekf.fix_floor_xy_m2": 0.25,
        "ekf.fix_bias_sigma_m": 1.25,
        "ekf.fix_bias_length_m": 12.0,
        "ekf.fix_white_share": 0.625,
    }
