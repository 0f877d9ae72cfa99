"""Crowd fit and solve at scale: the synthetic fleet, pair blocks on Dask, the crowd-scale bench."""

from __future__ import annotations

import json

import numpy as np
import pytest
from stridefix_analyzer.crowd import blocks as cbk
from stridefix_analyzer.crowd.fit import fit_walks
from stridefix_analyzer.crowd.walks import CrowdInputError, pool_scans
from stridefix_analyzer.parallel import dask_client, run_tasks
from stridefix_lab.bench import crowd_scale
from stridefix_lab.crowd.fleet import FleetSpec, make_fleet
from stridefix_lab.crowd.scale_solve import solve_walks_grouped, walk_groups


@pytest.fixture(scope="module")
def fleet():
    return make_fleet(FleetSpec(n_walks=12, n_scans=2400, seed=3))


@pytest.fixture(scope="module")
def client():
    with dask_client("local", 2) as c:
        yield c


def test_fleet_shapes(fleet):
    walks = fleet.walks
    assert len(walks) == 12
    assert sum(w.n_scans for w in walks) == 2400
    for w in walks:
        assert np.all(np.diff(w.scan_t_us) > 0) and np.all(np.diff(w.truth_t_us) > 0)
        assert len(w.ap_scan) == len(w.ap_bssid) == len(w.ap_rssi_dbm) == len(w.ap_freq_mhz)
        assert w.ap_scan.max() < w.n_scans
        assert not w.dense_truth and len(np.unique(w.truth_floor)) == 1
    s = pool_scans(walks)
    assert s.usable.all() and np.isfinite(s.xy_m).all()  # every scan hears an AP and has truth


def test_fleet_radio_physics(fleet):
    rss = np.concatenate([w.ap_rssi_dbm for w in fleet.walks])
    assert rss.min() >= -95 and np.array_equal(rss, np.round(rss))  # sensitivity, whole dBm
    # RSS falls with distance to the AP: near (< 8 m, same floor) vs far (> 30 m) readings
    near, far = [], []
    col = {int(b): k for k, b in enumerate(fleet.ap_bssid)}
    for w in fleet.walks:
        xy, fl = w.place(w.scan_t_us)
        k = np.array([col[int(b)] for b in w.ap_bssid])
        same = fleet.ap_floor[k] == fl[w.ap_scan]
        d = np.hypot(*(xy[w.ap_scan] - fleet.ap_xy_m[k]).T)
        near.append(w.ap_rssi_dbm[same & (d < 8)])
        far.append(w.ap_rssi_dbm[same & (d > 30)])
    assert np.mean(np.concatenate(near)) - np.mean(np.concatenate(far)) > 20
    assert len(np.concatenate(near)) > 100


def test_fleet_walking_and_dead_reckoning(fleet):
    for k, w in enumerate(fleet.walks):
        v = np.hypot(*np.diff(w.truth_xy_m, axis=0).T) / np.diff(w.truth_t_us * 1e-6)
        assert 1.0 < v.min() and v.max() < 1.6  # walking pace, ~1.3 m/s
        gaps = np.diff(w.scan_t_us) * 1e-6
        assert 1.4 < gaps.mean() < 2.6
        # a DR step is the true displacement since the previous step × the walk's stride scale
        xy, _ = w.place(w.step_t_us)
        true_len = np.sum(np.hypot(*np.diff(xy, axis=0).T))
        assert abs(np.sum(w.step_length_m[1:]) / true_len / fleet.stride_scale[k] - 1) < 0.01
        # a stride = walking speed × step period × stride scale
        stride = np.median(v) * fleet.spec.step_period_s * fleet.stride_scale[k]
        assert abs(np.median(w.step_length_m) / stride - 1) < 0.02


def test_bins_bit_identical_serial_and_dask(fleet, client):
    s = pool_scans(fleet.walks)
    settings = cbk.BinSettings(block=256)
    serial, info = cbk.bin_pairs_tasks(s.R, s.xy_m, s.floor, settings)
    assert info["block_pairs"] > 10  # several tasks, merged in order
    dask_bins, _ = cbk.bin_pairs_tasks(s.R, s.xy_m, s.floor, settings, client=client)
    legacy = cbk.bin_pairs(s.R, s.xy_m, s.floor, block=256)
    for b in (dask_bins, legacy):
        for k in ("count", "sum_x", "sum_d", "sum_d2"):
            assert np.array_equal(getattr(b, k), getattr(serial, k))
        assert (b.min_d, b.n_pairs, b.n_no_common) == (serial.min_d, serial.n_pairs, serial.n_no_common)
    # every same-floor pair binned exactly once
    n_floor = np.bincount(s.floor)
    assert serial.n_pairs + serial.n_no_common == int(np.sum(n_floor * (n_floor - 1) // 2))
    m1, _ = fit_walks(fleet.walks, precision="float32")
    m2, _ = fit_walks(fleet.walks, precision="float32", client=client)
    assert m1.params == m2.params and m1.extra["binning"]["dtype"] == "float32"


def test_pair_subsample_is_unbiased(fleet):
    s = pool_scans(fleet.walks)
    settings = cbk.BinSettings(block=128)
    full, _ = cbk.bin_pairs_tasks(s.R, s.xy_m, s.floor, settings)
    half, info = cbk.bin_pairs_tasks(s.R, s.xy_m, s.floor, settings, pair_fraction=0.5, seed=4)
    assert 0.4 < half.n_pairs / full.n_pairs < 0.6 and "unbiased random subsample" in info["sampling"]
    for f in ("sum_x", "sum_d"):  # mean dissimilarity and mean distance of the sample ≈ the full set's
        a, b = getattr(full, f).sum() / full.n_pairs, getattr(half, f).sum() / half.n_pairs
        assert abs(a / b - 1) < 0.05
    with pytest.raises(CrowdInputError):
        fit_walks(fleet.walks, pair_fraction=1.5)


def test_grouped_solve_matches_joint(fleet, client):
    walks = fleet.walks[:4]
    assert walk_groups(walks, "chunk:3") == [[0, 1, 2], [3]]
    per_walk = solve_walks_grouped(walks, "chunk:1", client=client)
    assert per_walk["n_groups"] == 4 and per_walk["rows"]["wifi"] == 0
    assert per_walk["error_non_anchor_truth"]["mean_m"] < 3.0  # DR between anchors every 40 s
    assert run_tasks(lambda t, shared: t * shared, [1, 2, 3], shared=2) == [2, 4, 6]


def test_bench_runs_small(tmp_path):
    doc = crowd_scale.run_crowd_scale(tmp_path, n_scans=600, n_walks=4)
    saved = json.loads((tmp_path / "crowd_scale.json").read_text())
    assert saved["fleet"]["scans"] == 600 and saved["fleet"]["walks"] == 4
    assert set(doc["fit"]) == {"serial", "dask_1", "dask_2"} and set(doc["solve"]) == {"serial", "dask_2"}
    assert all(f["identical"] for f in doc["fit"].values())
    assert doc["pairs_binned"] > 0 and doc["peak_rss_mb"]["main"] > 0
    assert [t["met"] for t in doc["targets"]] == [True, True]
    assert "targets:" in crowd_scale.format_table(doc)
