"""Candidate dissimilarity → distance models: features, forms, streaming fit, held-out selection, CLI.

GIVEN random scans, synthetic (feature, distance) pairs with known laws, and three SIL walkers
WHEN the features, fits, held-out selection and `crowd models` run on them
THEN the features match their per-pair definitions, each form recovers its parameters, the streamed
fit equals the one-shot fit, the held-out choice finds the law, and the model files round-trip."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd import models as mm
from stridefix_analyzer.crowd.features import FEATURES, features, iter_feature_blocks, pair_loop_features
from stridefix_analyzer.crowd.walks import Walk
from stridefix_lab.crowd import select_model as sm


def _walks_from_scans(R: np.ndarray, xy: np.ndarray, per_walk: int) -> list[Walk]:
    """Walks of ``per_walk`` consecutive scans each, truth exactly at the scan times (floor 0)."""
    out = []
    for w, s0 in enumerate(range(0, len(R), per_walk)):
        Rw, P = R[s0 : s0 + per_walk], xy[s0 : s0 + per_walk]
        rows, cols = np.nonzero(np.isfinite(Rw))
        t = np.arange(len(Rw), dtype=np.int64) * 1_000_000
        out.append(
            Walk(
                name=f"w{w:02d}",
                scan_t_us=t,
                ap_scan=rows.astype(np.int64),
                ap_bssid=cols.astype(np.int64) + 100,
                ap_rssi_dbm=Rw[rows, cols],
                ap_freq_mhz=np.full(len(rows), 2437, np.int64),
                truth_t_us=t,
                truth_xy_m=P,
                truth_floor=np.zeros(len(t), np.int64),
                dense_truth=True,
                step_t_us=np.zeros(0, np.int64),
                step_length_m=np.zeros(0),
                step_heading_rad=np.zeros(0),
            )
        )
    return out


def _path_loss_world(seed: int = 3, n: int = 240, aps: int = 30):
    """Scans on a 60 × 30 m floor hearing APs by a log-distance law (σ 3 dB), −90 dBm threshold."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform([0, 0], [60, 30], size=(n, 2))
    ap = rng.uniform([0, 0], [60, 30], size=(aps, 2))
    dist = np.hypot(*(xy[:, None, :] - ap[None, :, :]).transpose(2, 0, 1))
    R = -40.0 - 30.0 * np.log10(np.maximum(dist, 1.0)) + rng.normal(0, 3.0, dist.shape)
    R[R < -90.0] = np.nan
    return R, xy


# --- features --------------------------------------------------------------------------------------


def test_features_match_per_pair_loop(random_scans):
    R, _, _ = random_scans
    F, nc = features(R)
    for i in range(len(R)):
        for j in range(len(R)):
            ref = pair_loop_features(R[i], R[j])
            assert nc[i, j] == np.sum(np.isfinite(R[i]) & np.isfinite(R[j]))
            for name in FEATURES:
                assert_allclose(F[name][i, j], ref[name], rtol=1e-9, atol=1e-9, equal_nan=True)
    assert np.isnan(F["jaccard"][5, 6])  # no AP in common


def test_feature_blocks_cover_lower_triangle(random_scans):
    R, _, _ = random_scans
    F, nc = features(R)
    seen = np.zeros(nc.shape, bool)
    for i0, j0, f, n, keep in iter_feature_blocks(R, ("cosine", "common_rms"), block=7):
        bi, bj = keep.shape
        assert_allclose(f["cosine"][keep], F["cosine"][i0 : i0 + bi, j0 : j0 + bj][keep], atol=1e-12)
        assert_allclose(n, nc[i0 : i0 + bi, j0 : j0 + bj])
        seen[i0 : i0 + bi, j0 : j0 + bj] |= keep
    assert np.array_equal(seen, np.tril(nc > 0.5, -1))


# --- forms -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "form,params,x_max",
    [
        ("thesis", {"X": [1.0, -5.0, 2.0]}, 20.0),
        ("linear", {"a": 3.0, "b": 1.5}, 20.0),
        ("log", {"a": 2.0, "b": 10.0, "x0": 2.0}, 30.0),
        ("saturating", {"A": 40.0, "B": 0.2, "C": 2.0}, 1.0),
        ("power", {"a": 1.0, "b": 20.0, "p": 2.0, "xs": 0.5}, 1.0),
    ],
)
def test_each_form_recovers_known_parameters(form, params, x_max):
    rng = np.random.default_rng(11)
    x = rng.uniform(0.0, x_max, 60_000)
    d = mm.form_predict(form, params, x) + rng.normal(0.0, 0.5, x.size)
    bins = cm.PairBins(width=x_max / 400)
    bins.add(x, d)
    if form == "thesis":
        bins.min_d = 1.0  # X1's upper bound, the smallest true distance: 1 m in this world (noise aside)
    got = mm.fit_form(form, bins)
    grid = np.linspace(0.0, x_max, 50)
    # the fitted curve, not each parameter (power's b and xs trade off), within 0.3 m
    assert np.max(np.abs(mm.form_predict(form, got, grid) - mm.form_predict(form, params, grid))) < 0.3
    if form != "power":
        for k, v in params.items():
            assert_allclose(np.asarray(got[k]), np.asarray(v), rtol=0.05, atol=0.1)


def test_isotonic_is_monotone_and_sigma_tracks_the_noise():
    rng = np.random.default_rng(5)
    x = rng.uniform(0.0, 1.0, 50_000)
    d = 30.0 * x**2 + rng.normal(0.0, np.sqrt(1.0 + 20.0 * x))  # variance linear in x, σ's model
    bins = cm.PairBins(width=0.005)
    bins.add(x, d)
    p = mm.fit_form("isotonic", bins)
    assert np.all(np.diff(p["y"]) >= -1e-9)
    s = mm.sigma_predict(mm.fit_sigma("isotonic", p, bins), np.array([0.1, 0.9]))
    assert_allclose(s, np.sqrt([3.0, 19.0]), rtol=0.1)


def test_streaming_fit_equals_fit_on_all_pairs():
    rng = np.random.default_rng(2)
    x = rng.uniform(0.0, 1.0, 30_000)
    d = 5.0 + 30.0 * x + rng.normal(0.0, 3.0, x.size)
    one, chunks = cm.PairBins(width=0.0025), cm.PairBins(width=0.0025)
    one.add(x, d)
    for part in np.array_split(np.arange(x.size), 17):
        chunks.add(x[part], d[part])
    c = mm.Candidate("cosine", "linear")
    a, b = mm.fit_candidate(c, [one]), mm.fit_candidate(c, [chunks])
    assert_allclose([a.params[0]["a"], a.params[0]["b"]], [b.params[0]["a"], b.params[0]["b"]], rtol=1e-9)
    slope, icpt = np.polyfit(x, d, 1)  # pair-level OLS: equal up to the bin-mean replacement
    assert_allclose([a.params[0]["a"], a.params[0]["b"]], [icpt, slope], rtol=2e-3, atol=2e-2)
    r = d - (icpt + slope * x)
    assert_allclose(a.fit["r2"], 1 - np.sum(r * r) / np.sum((d - d.mean()) ** 2), atol=1e-3)


def test_bin_by_fold_does_not_depend_on_the_block_size():
    R, xy = _path_loss_world(n=90)
    walks = _walks_from_scans(R, xy, 10)
    fw = sm.walk_folds(walks, 3)
    big, _, info = sm.bin_by_fold(walks, fw, 3, ("cosine",), block=2048)
    small, _, _ = sm.bin_by_fold(walks, fw, 3, ("cosine",), block=16)
    for c_big, c_small in zip(big["cosine"], small["cosine"], strict=True):
        for a, b in zip(c_big, c_small, strict=True):
            assert a.n_pairs == b.n_pairs
            assert_allclose(a.sum_d, b.sum_d, rtol=1e-12)
    assert info["pairs"] > 1000


# --- held-out selection ---------------------------------------------------------------------------


def test_heldout_selection_picks_the_true_law():
    """GIVEN pairs whose distance is a saturating function of the cosine feature (σ 3 m), in 5 folds
    WHEN the thesis, linear, log and saturating forms are scored on held-out pairs
    THEN saturating wins and its held-out R² is near the noise-limited value."""
    rng = np.random.default_rng(8)
    K, n = 5, 80_000
    x = rng.uniform(0.0, 1.0, n)
    true = {"A": 40.0, "B": 0.15, "C": 2.0}
    d = mm.form_predict("saturating", true, x) + rng.normal(0.0, 3.0, n)
    fi, fj = rng.integers(0, K, n), rng.integers(0, K, n)
    nc = rng.integers(1, 12, n)
    cat_of = sm._cat_index(K)
    n_cat = int(cat_of.max()) + 1
    st = mm.stratum_of(nc, mm.STRATA_EDGES)
    bins = {"cosine": [[cm.PairBins(width=0.0025) for _ in mm.STRATA_EDGES] for _ in range(n_cat)]}
    for c in range(n_cat):
        for s in range(len(mm.STRATA_EDGES)):
            m = (cat_of[fi, fj] == c) & (st == s)
            if m.any():
                bins["cosine"][c][s].add(x[m], d[m])
    sample = {"d": d, "n_common": nc, "fold_i": fi, "fold_j": fj, "cosine": x}
    cands = [mm.Candidate("cosine", f) for f in ("thesis", "linear", "log", "saturating")]
    rows, fitted, folds, _ = sm.score_candidates(bins, sample, K, cands, lambda s: None)
    assert rows[0]["name"] == "saturating/cosine"
    expect = 1 - 9.0 / np.var(d)
    assert abs(rows[0]["heldout_r2"] - expect) < 0.02
    assert rows[-1]["heldout_r2"] < rows[0]["heldout_r2"] - 0.05
    assert_allclose(fitted["saturating/cosine"].params[0]["B"], 0.15, rtol=0.1)
    assert all(len(v) == K for v in folds.values())


def test_select_model_on_walks_with_position_hook():
    R, xy = _path_loss_world()
    walks = _walks_from_scans(R, xy, 24)
    calls = []

    def score(model, held):
        calls.append((model.name, len(held)))
        return 1.0 if model.name.startswith("isotonic") else 2.0

    cands = ["thesis/common_sum", "linear/common_rms", "isotonic/cosine", "linear/union_rms@n*"]
    sel = sm.select_model(walks, cands, folds=5, score_positions=score)
    assert {r["name"] for r in sel.rows} == set(cands)
    assert all(np.isfinite(r["heldout_r2"]) and r["heldout_pairs"] > 1000 for r in sel.rows)
    r2 = {r["name"]: r["heldout_r2"] for r in sel.rows}
    assert r2["isotonic/cosine"] > 0.3 and r2["isotonic/cosine"] > r2["thesis/common_sum"]
    assert len(calls) == 3 * 5 and all(k == 2 for _, k in calls)  # top 3 × 5 folds of 2 walks
    assert sel.best.name == "isotonic/cosine" and "position" in sel.chosen_by
    assert "(ref)" in sm.format_table(sel)


# --- the PairModel protocol ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def fitted_models():
    R, xy = _path_loss_world(n=120)
    walks = _walks_from_scans(R, xy, 20)
    sel = sm.select_model(walks, ["power/cosine@n*", "isotonic/jaccard", "thesis/common_sum"], folds=3)
    return sel.fitted, R


def test_predict_shapes_nan_and_positive_sigma(fitted_models, random_scans):
    models, _ = fitted_models
    R, _, _ = random_scans
    Ra, Rb = R[:9], R[3:20]
    _, nc = features(Ra, Rb)
    for m in models.values():
        g, s = m.predict(Ra, Rb)
        assert g.shape == s.shape == (9, 17)
        assert np.array_equal(np.isfinite(g), nc > 0.5) and np.array_equal(np.isfinite(s), nc > 0.5)
        assert np.all(s[np.isfinite(s)] > 0)


def test_min_common_aps_masks_pairs(fitted_models, random_scans):
    models, _ = fitted_models
    R, _, _ = random_scans
    m = models["isotonic/jaccard"]
    m.min_common_aps = 3
    g, _ = m.predict(R, R)
    _, nc = features(R)
    assert np.array_equal(np.isfinite(g), nc >= 3)
    m.min_common_aps = 1


def test_json_round_trip(fitted_models, random_scans):
    models, _ = fitted_models
    R, _, _ = random_scans
    for m in models.values():
        back = mm.model_from_json(json.loads(json.dumps(m.to_json())))
        assert back.name == m.name
        for a, b in zip(m.predict(R, R), back.predict(R, R), strict=True):
            assert_allclose(a, b, equal_nan=True)


def test_thesis_distance_model_is_a_pair_model(random_scans):
    R, _, _ = random_scans
    dm = cm.DistanceModel(floor_m=1.0, intercept_m=-2.0, slope_m_per_db=0.5, rmse_m=3.0)
    pm = mm.model_from_json(json.loads(json.dumps(dm.to_json())))
    g, s = pm.predict(R, R)
    assert pm.name == "thesis/common_sum"
    assert_allclose(g, dm(cm.dissimilarity(R)), equal_nan=True)
    assert_allclose(s[np.isfinite(g)], 3.0)
    back = mm.model_from_json(json.loads(json.dumps(pm.to_json())))
    assert_allclose(back.predict(R, R)[0], g, equal_nan=True)


# --- CLI -------------------------------------------------------------------------------------------


def test_crowd_models_cli_on_sil_walks(sil_walks, cli, tmp_path, lab):
    proc = lab("crowd", "models", *sil_walks, "--folds", "3", "--out", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "models.json").read_text())
    names = [r["name"] for r in doc["rows"]]
    assert len(names) == len(mm.ALL_CANDIDATES) and doc["reference"] in names
    assert doc["best"]["name"] == names[0] and doc["info"]["folds"] == 3
    assert all(r["heldout_pairs"] > 100 for r in doc["rows"] if np.isfinite(r["heldout_r2"]))
    assert mm.model_from_json(doc["best"]).name == names[0]
    assert (tmp_path / "models.png").stat().st_size > 5000
    assert "best:" in proc.stdout and "(ref)" in proc.stdout
