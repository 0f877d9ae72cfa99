"""``stridefix-lab bench perf``'s scikit-learn peer on a real map (bench/perf_knn_real.py): the harness
``sf_site_match`` loads a site file with the board's loader, matches each query scan alone and dumps the
levels it compares, so sklearn on that dump reproduces the C matcher wherever both consider the same RPs.
A small grid site stands in for the msindoor floor (the whole floor is bench perf's, ~30 s)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from stridefix_analyzer.io.sitefile import new_site, write_site
from stridefix_lab.bench import perf_knn_real, perf_peers


def _grid_site(path):
    """A 6 × 6 grid of RPs 3 m apart, 8 APs, one entry wherever the level is above −85 dBm,
    two scans per RP that both heard it (map level = mean); returns (AP positions, BSSIDs)."""
    rng = np.random.default_rng(7)
    ap_xy = rng.uniform(0.0, 15.0, size=(8, 2))
    bssid = 0x0000A0B0C0000000 + np.arange(8)
    rp = np.array([(3.0 * i, 3.0 * j) for j in range(6) for i in range(6)])
    ea, er, em = [], [], []
    for a in range(8):  # entries sorted by (ap, rp)
        for r in range(len(rp)):
            level = -40.0 - 30.0 * math.log10(max(np.hypot(*(rp[r] - ap_xy[a])), 1.0))
            if level > -85.0:
                ea.append(a), er.append(r), em.append(level)
    site = new_site(
        ap_bssid=bssid,
        rp_x_m=rp[:, 0],
        rp_y_m=rp[:, 1],
        rp_floor=np.zeros(len(rp), int),
        rp_scans=np.full(len(rp), 2),
        entry_ap=ea,
        entry_rp=er,
        entry_mean_dbm=em,
        entry_std_db=[3.0] * len(ea),
        entry_count=[2] * len(ea),
    )
    write_site(path, site)
    return ap_xy, bssid


def test_site_match_dump_reproduces_the_c_matcher_with_sklearn(stridefixd, tmp_path):
    """GIVEN a grid site and 30 scans at random points (every AP above −80 dBm, 3 dB noise), plus one scan
    of an AP the map does not know and one below min_rssi THEN the harness fixes every scan, drops those
    two readings from its dump, and sklearn's distance-weighted 3-NN on the dump gives the C fixes."""
    harness = perf_knn_real.site_match_path(stridefixd)
    if not harness.is_file():
        pytest.fail(f"{harness} not built: run `make build`")
    site = tmp_path / "grid.sfsite"
    ap_xy, bssid = _grid_site(site)
    rng = np.random.default_rng(11)
    lines = []
    for _ in range(30):
        q = rng.uniform(1.0, 14.0, size=2)
        levels = -40.0 - 30.0 * np.log10(np.maximum(np.hypot(*(ap_xy - q).T), 1.0)) + 3.0 * rng.normal(size=8)
        readings = [(int(b), round(v)) for b, v in zip(bssid, levels) if v > -80.0]
        readings += [
            (0x0000FFFF00000001, -50),
            (int(bssid[0]), -95),
        ]  # an AP the map lacks; a second, weaker reading of AP 0 below min_rssi
        lines.append(f"q {q[0]:.6f} {q[1]:.6f} {len(readings)} " + " ".join(f"{b} {v}" for b, v in readings))
    queries = tmp_path / "queries.txt"
    queries.write_text("\n".join(lines) + "\n")
    pre = perf_knn_real._run_harness(harness, site, queries, tmp_path / "dump.txt", full=False)  # noqa: SLF001
    full = perf_knn_real._run_harness(harness, site, queries, tmp_path / "dump.full.txt", full=True)  # noqa: SLF001
    assert full["summary"]["scans"] == 30 and full["summary"]["fixes"] == 30
    assert full["summary"]["mean_heard"] - full["summary"]["mean_used"] >= 2.0 - 1e-9  # the two left out
    doc = perf_peers.compare_knn(pre, full, repeats=1)
    assert doc["n_rp"] == 36 and doc["n_ap"] <= 8
    assert doc["same_fix_fraction"] == 1.0 and doc["full_visit_vs_sklearn_max_m"] < 1e-3
    assert doc["sklearn_mean_error_m"] == pytest.approx(doc["ours_full_visit"]["mean_error_m"], abs=1e-3)
    assert doc["ours_preselect"]["queries_per_s"] > 0.0


def test_site_match_names_a_bad_query_line(stridefixd, tmp_path):
    harness = perf_knn_real.site_match_path(stridefixd)
    site = tmp_path / "grid.sfsite"
    _grid_site(site)
    queries = tmp_path / "queries.txt"
    queries.write_text("q 1 2 1 7 -50\nwhat is this\n")
    with pytest.raises(perf_peers.StageError, match=r"queries.txt: line after scan 1"):
        perf_knn_real._run_harness(harness, site, queries, tmp_path / "dump.txt", full=False)  # noqa: SLF001
