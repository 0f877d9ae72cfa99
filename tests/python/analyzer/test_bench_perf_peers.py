"""``stridefix-lab bench perf``'s Python peers (bench/perf_peers.py) on small inputs: Madgwick and Fusion run
on the harness's samples and agree on the yaw, and scikit-learn's KNN reads the harness's own map and
scans so that it reproduces the C matcher's exact (full-visit) WkNN fixes."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from stridefix_lab.bench import perf_peers


def test_madgwick_and_fusion_run_per_sample_and_agree_on_the_yaw(harness, tmp_path):
    """GIVEN 10 s of the sensors walk THEN both filters take every sample at a positive cost and their
    yaws, once Fusion's start-up ramp is over, agree within 10° (both settle on the field's heading)."""
    samples = tmp_path / "samples.txt"
    samples.write_text(
        subprocess.run([str(harness), "samples", "10"], capture_output=True, text=True, check=True).stdout
    )
    att = perf_peers.measure_madgwick_peer(samples, repeats=1)
    assert att["samples"] == 1000
    assert 0.0 < att["fusion_python_us_per_sample"] < 1000.0
    assert 0.0 < att["madgwick_us_per_sample"] < 10_000.0
    assert att["yaw_rms_diff_deg"] < 10.0


def test_our_heading_agrees_with_fusion_on_the_same_samples(harness, tmp_path):
    """GIVEN 20 s of the sensors walk and our attitude's yaw on it (sf_core_cost yaw) THEN after the
    settle time ours and Fusion's (its NWU yaw turned to our ENU) agree within a generous 10° RMS and
    20° max: both follow the same field (120 s in bench perf: ~3.4° RMS, the gyro/magnetometer tug of
    war of the walk weighed a little differently)."""
    samples, yaw = tmp_path / "samples.txt", tmp_path / "yaw.txt"
    for path, mode in ((samples, "samples"), (yaw, "yaw")):
        path.write_text(
            subprocess.run([str(harness), mode, "20"], capture_output=True, text=True, check=True).stdout
        )
    att = perf_peers.measure_madgwick_peer(samples, repeats=1, ours_yaw=yaw)
    assert att["ours_vs_fusion_yaw_rms_deg"] < 10.0
    assert att["ours_vs_fusion_yaw_max_abs_deg"] < 20.0
    assert abs(att["ours_vs_fusion_yaw_mean_deg"]) <= att["ours_vs_fusion_yaw_rms_deg"]
    assert "ours vs Fusion: RMS" in perf_peers.format_rows(att, _KNN_ROW)[0]


def test_our_yaw_file_must_be_on_the_sample_times(tmp_path):
    """A yaw file of another walk (other times or length) is refused, not compared."""
    bad = tmp_path / "yaw.txt"
    bad.write_text("0.00 1.0\n0.02 1.0\n")
    with pytest.raises(perf_peers.StageError, match=r"yaw.txt: want 't_s yaw_rad'"):
        perf_peers.read_yaw(bad, np.array([0.0, 0.01]))


#: a KNN peer row's fields, for formatting the attitude row beside it
_KNN_ROW = {
    "ours_preselect": {"mean_error_m": 1.0, "queries_per_s": 1.0, "fixes": 1},
    "ours_full_visit": {"mean_error_m": 1.0, "queries_per_s": 1.0, "fixes": 1},
    "n_rp": 1,
    "n_ap": 1,
    "scans": 1,
    "sklearn_mean_error_m": 1.0,
    "sklearn_queries_per_s_batch": 1.0,
    "sklearn_queries_per_s_single": 1.0,
    "same_fix_fraction": 1.0,
}


def test_knn_on_the_harness_map_matches_the_full_visit(harness, tmp_path):
    """GIVEN the 100-RP map and 20 scans THEN sklearn's distance-weighted 3-NN on the dense −100 dBm
    fingerprints gives the C full visit's fixes (to float rounding), and every rate is positive."""
    knn = perf_peers.measure_knn_peer(harness, tmp_path, n_rp=100, n_scans=20, repeats=1)
    assert (knn["n_rp"], knn["scans"]) == (100, 20)
    assert knn["ours_full_visit"]["fixes"] == 20
    assert knn["full_visit_vs_sklearn_max_m"] < 1e-3
    assert knn["sklearn_mean_error_m"] == pytest.approx(knn["ours_full_visit"]["mean_error_m"], abs=1e-3)
    assert 0.0 <= knn["sklearn_mean_error_m"] < 8.0
    for rate in (
        knn["sklearn_queries_per_s_batch"],
        knn["sklearn_queries_per_s_single"],
        knn["ours_preselect"]["queries_per_s"],
    ):
        assert rate > 0.0


def test_wifidump_lines_that_are_not_rp_e_or_q_are_named(tmp_path):
    bad = tmp_path / "dump.txt"
    bad.write_text("rp 0 1 1\ne 0 0 -50\nx what\n")
    with pytest.raises(perf_peers.StageError, match=r"dump.txt:3"):
        perf_peers.read_wifidump(bad)
