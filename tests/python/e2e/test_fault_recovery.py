"""The firmware survives bus and board faults, end to end: a 90 s SIL walk from the
simulator's fault injector through the real stridefixd, without a site (PDR alone, so nothing can hide a
lost step). Each fault costs only the frames it touches: steps and PDR error stay with the clean run's,
the walk carries on to its end, and the fault's own HEALTH counter moves. A failed IMU costs the walk's
steps from then on, and nothing else: the daemon logs on to the end. (`make reliability` is the
full-length table; this is its regression test.)"""

from __future__ import annotations

import pytest
from stridefix_analyzer.firmware import Firmware
from stridefix_lab.bench import reliability

CASES = [
    ("clean", "-", {}),
    ("reset", "at 40 s", {"faults": {"reset_at_s": [40.0]}}),
    ("implausible", "1 bit at 50 s", {"faults": {"implausible_at_s": [50.0]}}),
    ("corrupt", "1 %", {"faults": {"corrupt_rate": 0.01}}),
    ("duplicate", "2 %", {"faults": {"duplicate_rate": 0.02}}),
    ("reorder", "1 % by 1", {"faults": {"reorder_rate": 0.01, "reorder_frames": 1}}),
    ("silence", "5 s at 60 s", {"faults": {"silence_at_s": [60.0], "silence_s": 5.0}}),
    (
        "board_time_stuck",
        "30 s at 30 s",
        {"faults": {"board_time_stuck_at_s": [30.0], "board_time_stuck_s": 30.0}},
    ),
    ("imu_failed", "from 60 s", {"faults": {"imu_failed_at_s": [60.0], "imu_failed_s": 3600.0}}),
]
#: the faults that leave the walk's steps and error as the clean run's (a failed IMU cannot)
COSTLESS = [c[0] for c in CASES[1:] if c[0] != "imu_failed"]
# the counter each fault must move (HEALTH field, read from the log)
COUNTER = {
    "reset": "board_restarts",
    "implausible": "samples_jumped",
    "duplicate": "duplicates",
    "silence": "gaps_bridged",
    "board_time_stuck": "board_time_rejected",
    "imu_failed": "samples_out_of_range",
}


@pytest.fixture(scope="module")
def rows(stridefixd, tmp_path_factory):
    out = tmp_path_factory.mktemp("fault_recovery")
    doc = reliability.run_reliability(Firmware(stridefixd), out, CASES, site=False, duration_s=90.0)
    return {r["fault"]: r for r in doc["cases"]}


@pytest.mark.parametrize("fault", COSTLESS)
def test_fault_costs_only_its_frames(rows, fault):
    clean, row = rows["clean"], rows[fault]
    assert clean["steps"] > 100
    # silence: the steps inside the 5 s window cannot be detected (about 9 at this pace)
    allowed = 12 if fault == "silence" else max(2, round(0.02 * clean["steps"]))
    assert abs(row["steps"] - clean["steps"]) <= allowed, (row["steps"], clean["steps"])
    assert row["steps_last_30s"] >= 0.8 * clean["steps_last_30s"]  # dead reckoning carried on
    err, err_clean = row["mean_error_m"]["pdr_only"], clean["mean_error_m"]["pdr_only"]
    assert err <= 1.5 * err_clean + 1.0, (err, err_clean)
    assert row["checks"]["recovered"]
    if fault in COUNTER:
        assert row["health"][COUNTER[fault]] >= 1
        assert clean["health"][COUNTER[fault]] == 0


def test_reset_is_counted_once_and_time_goes_on(rows):
    assert rows["reset"]["health"]["board_restarts"] == 1
    assert rows["reset"]["health"]["board_time_rejected"] == 0
    assert rows["corrupt"]["health"]["board_restarts"] == 0  # a corrupt BOARD_TIME is not a reset


def test_stuck_board_time_is_not_believed_and_times_stay(rows):
    """GIVEN BOARD_TIME stuck at one value for 30 s while the samples go on WHEN replayed THEN no
    restart is believed (each stuck frame was one), no sample is out of order, and after the fault
    every IMU sample's output time is the clean run's (a 28 s shift for the rest of the walk before:
    the analyzer matches by time)."""
    row = rows["board_time_stuck"]
    h = row["health"]
    assert h["board_restarts"] == 0 and h["board_time_jumps"] == 0 and h["samples_out_of_order"] == 0
    assert h["board_time_rejected"] == row["sim_faults"]["board_time_stuck"] == 29
    m = row["measures"]
    assert m["imu_after_matched"] == m["imu_after_clean"] > 2000
    assert m["time_offset_after_max_ms"] < 10.0
    assert row["checks"]["times_after"] and row["checks"]["error_after"] and row["checks"]["recovered"]


def test_failed_imu_stops_steps_and_the_daemon_logs_on(rows):
    """GIVEN every IMU signal at full scale from 60 s to the end WHEN replayed THEN stridefixd
    refuses the samples (counted), detects no step after the failure and logs to the walk's end."""
    row = rows["imu_failed"]
    assert row["health"]["samples_out_of_range"] >= row["sim_faults"]["imu_failed"] // 2 > 2000
    checks = row["checks"]
    assert checks["steps_stop"] and checks["logging"]
    assert checks["wifi_fixes"] is None  # no site here: no Wi-Fi fix
    assert checks["steps"] is None and checks["error"] is None  # the common checks do not apply


def test_failed_imu_does_not_flood_the_log_with_poses(rows):
    # stridefixd writes a pose when the estimator has a new one, not for every sample the gate refuses
    assert rows["imu_failed"]["checks"]["pose_volume"]
