"""``stridefix-lab bench perf`` (bench/perf.py) and its harness ``sf_core_cost`` (tests/perf/core_cost.c):
the harness drives the real core calls (steps come out of the walk, every fix lands near its scan),
callgrind's count is read per call, and the budgets are judged from the figures, not hard-coded."""

from __future__ import annotations

import pytest
from stridefix_analyzer.firmware import Firmware
from stridefix_lab.bench import perf


def test_sensor_walk_runs_the_pdr_at_the_board_rates(harness):
    """GIVEN 30 s at 100/50/20 Hz with a 1.8 Hz gait THEN every sample reached the core and the PDR
    counted the gait's steps (the cost is of a working estimator, not of an idle one)."""
    w = perf._harness_json(harness, "sensors", "30")
    assert (w["imu"], w["mag"], w["baro"]) == (3000, 1500, 600)
    assert 40 <= w["steps"] <= 56  # 28 s of walking at 1.8 Hz ≈ 50 steps, bouts confirmed


def test_wifi_maps_grow_with_constant_density_and_fixes_land_near_the_scan(harness):
    small = perf._harness_json(harness, "wifi", "100", "20")
    big = perf._harness_json(harness, "wifi", "2000", "20")
    assert small["n_rp"] == 100 and big["n_rp"] == 2025  # a square grid: 45²
    assert 150 < big["n_ap"] < 250 and 25 < big["mean_heard"] < 45
    for m in (small, big):
        assert m["fixes"] == 20 and 0.0 <= m["mean_error_m"] < 8.0


def test_wifi_preselection_scores_few_rps_and_keeps_the_accuracy(harness):
    """GIVEN the 2 025-RP map, the same 20 scans with stridefixd's workspace and with the full visit THEN
    the pre-selection decides every fix, scores at most preselect_rps (32) RPs of the ~1 500 the full
    visit scores, and its mean error is no worse than the full visit's by more than 0.3 m."""
    pre = perf._harness_json(harness, "wifi", "2000", "20")
    full = perf._harness_json(harness, "wifi", "2000", "20", "full")
    assert pre["preselect"] is True and full["preselect"] is False
    assert full["preselected"] == 0 and full["mean_scored"] > 1000
    assert pre["preselected"] == pre["fixes"] and pre["mean_scored"] <= 32
    assert pre["mean_error_m"] <= full["mean_error_m"] + 0.3


def test_wifi_heard_sweeps_the_aps_a_scan_hears_on_the_same_map(harness):
    """GIVEN the 2 025-RP map and scans of rising sensitivity THEN the map stays the same, the scans hear
    more APs (the -80 dBm rows are the map-size rows' scans), and the -80 and -85 dBm scans are pre-selected."""
    rows = [perf._harness_json(harness, "wifiheard", "2000", "10", f"{h:g}") for h in (-70, -80, -85)]
    assert {(r["n_rp"], r["n_entries"]) for r in rows} == {(2025, rows[0]["n_entries"])}
    heard = [r["mean_heard"] for r in rows]
    assert heard == sorted(heard) and heard[0] < 15 < heard[1] < 45 < heard[2]
    base = perf._harness_json(harness, "wifi", "2000", "10")
    assert rows[1]["mean_heard"] == base["mean_heard"] and rows[1]["mean_error_m"] == base["mean_error_m"]
    assert rows[1]["preselected"] == rows[1]["fixes"] and rows[2]["preselected"] == rows[2]["fixes"]
    with pytest.raises(perf.StageError):
        perf._harness_json(harness, "wifiheard", "2000", "10", "-20")  # a scan cannot hear above the APs


def test_callgrind_counts_the_matcher_per_fix(harness, tmp_path):
    """GIVEN 5 fixes on the 100-RP map under callgrind THEN the matcher's instructions are counted, and
    doubling the fixes roughly doubles them (per-call cost, not the harness's set-up)."""
    ir5 = perf._callgrind(harness, ("sf_fingerprint_match",), ("wifi", "100", "5"), tmp_path / "a.cg")
    ir10 = perf._callgrind(harness, ("sf_fingerprint_match",), ("wifi", "100", "10"), tmp_path / "b.cg")
    assert 1_000 < ir5 / 5 < 5_000_000
    assert 1.6 < ir10 / ir5 < 2.4


def test_the_attitude_peer_runs_on_the_same_samples(harness, tmp_path, monkeypatch):
    """GIVEN 10 s of the sensors walk THEN x-io Fusion's update is counted once per IMU sample, at the
    few hundred instructions its C code costs (not Python's interpreter around it)."""
    monkeypatch.setattr(perf, "SENSOR_SECONDS", 10)
    peer = perf.measure_attitude_peer(harness, tmp_path)
    assert peer["samples"] == 1000
    # our yaw on the same walk, one line per sample, for the heading agreement with Fusion
    assert len((tmp_path / "perf.yaw.txt").read_text().splitlines()) == 1000
    assert 100 < peer["ir_per_sample"] < 2000


def test_core_has_no_heap_symbols(stridefixd):
    heap = perf.check_no_heap(stridefixd)
    assert heap["met"], heap["message"]


def test_replay_reads_its_own_rss_not_the_forked_python(stridefixd, tmp_path, monkeypatch):
    monkeypatch.setattr(perf, "REPLAY_SECONDS", 30)
    r = perf.measure_replay(Firmware(stridefixd), tmp_path)
    assert r["walk_s"] == pytest.approx(30.0, abs=1.0)
    assert r["x_realtime"] > 10.0 and r["log_bytes"] > 0
    # the daemon's own CPU time (wait4): positive, and at most its wall time on this machine's 2 cores
    assert 0.0 < r["cpu_s"] <= 2.0 * r["wall_s"] + 0.05
    assert r["x_realtime_cpu"] == pytest.approx(r["walk_s"] / r["cpu_s"])
    assert 0 < r["peak_rss_kB"] < 64 * 1024  # the daemon is a few MB; the Python parent is > 100 MB
    assert r["analyze_s"] > 0


def test_budgets_are_judged_from_the_figures():
    values = {
        "imu_all_ir": 1199.0,
        "attitude_vs_fusion": 5.2,
        "wifi_2000_ir": 150_001.0,
        "wifi_scaling": 1.5,
        "estimator_B": 37552,
        "core_no_heap": True,
        "replay_x_realtime": 4999.0,
        "peak_rss_kB": 4528,
        "analyze_s": 6.9,
    }
    doc = {"budgets": perf.judge(values)}
    verdict = {b["key"]: b["met"] for b in doc["budgets"]}
    assert verdict == {
        "imu_all_ir": True,
        "attitude_vs_fusion": False,
        "wifi_2000_ir": False,
        "wifi_scaling": True,  # the bound itself meets "<="
        "estimator_B": False,
        "core_no_heap": True,
        "replay_x_realtime": False,
        "peak_rss_kB": True,
        "analyze_s": False,
    }
    assert (
        "perf: Wi-Fi fix at ~2 000 RPs [instructions] = 150001.0 (budget <= 150000)"
        in perf.missed_targets(doc)
    )
    assert len(perf.missed_targets(doc)) == 5


def test_scheme_costs_per_step_and_fix(stridefixd, tmp_path):
    """GIVEN particle-cost's walk through the ekf and the particle scheme under callgrind THEN each has a
    per-step and per-fix count, and the cloud of 1 000 particles costs far more per step than the ekf's
    3-state filter."""
    if not perf.particle_cost.harness_path(stridefixd).is_file():
        pytest.skip("sf_particle_cost not built")
    rows = perf.measure_schemes(stridefixd, tmp_path)
    assert set(rows) == {"ekf", "particle"}
    for r in rows.values():
        assert r["ir_per_step"] > 0 and r["ir_per_fix"] > 0
    assert rows["particle"]["ir_per_step"] > 50 * rows["ekf"]["ir_per_step"]
