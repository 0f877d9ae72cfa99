"""``stridefix-lab bench reliability`` and ``bench soak``: the harness machinery on short walks through the
real stridefixd (what the firmware survives is the bench's output, not asserted here), and the
recovery rule on made-up rows."""

from __future__ import annotations

import argparse
import json

import pytest
from stridefix_analyzer.firmware import Firmware
from stridefix_lab.bench import cli as bench_cli
from stridefix_lab.bench import reliability, soak

CASES = [
    ("clean", "-", {}),
    ("reset", "at 20 s", {"faults": {"reset_at_s": [20.0]}}),
    ("duplicate", "2 %", {"faults": {"duplicate_rate": 0.02}}),
]


@pytest.fixture(scope="module")
def short_reliability(stridefixd, tmp_path_factory):
    """GIVEN a 40 s walk, clean, with a board reset and with duplicates, replayed without a site."""
    out = tmp_path_factory.mktemp("reliability")
    return reliability.run_reliability(Firmware(stridefixd), out, CASES, site=False, duration_s=40.0), out


def test_reliability_writes_one_row_per_case(short_reliability):
    doc, out = short_reliability
    assert json.loads((out / "reliability.json").read_text())["cases"] == json.loads(
        json.dumps(doc["cases"], default=float)
    )
    assert [(r["fault"], r["rate"]) for r in doc["cases"]] == [(n, r) for n, r, _ in CASES]
    clean, reset, dup = doc["cases"]
    assert clean["checks"]["recovered"] and clean["counters_moved"] == {} and clean["health_diff"] == {}
    assert clean["frames_lost"] == 0 and clean["frames_affected"] == 0
    # the simulator's ground truth reaches the row
    assert (
        reset["sim_faults"]["resets"] == 1
        and reset["frames_affected"] == reset["sim_faults"]["frames_affected"]
    )
    assert dup["frames_affected"] == dup["sim_faults"]["duplicated"] > 0
    assert dup["frames_received"] == clean["frames_received"] + dup["sim_faults"]["duplicated"]
    # HEALTH read generically: every integer counter, and the ones that moved against the clean run
    assert {"frames_total", "frames_ok", "imu_samples"} <= set(clean["health"])
    assert dup["health_diff"]["frames_total"] == dup["sim_faults"]["duplicated"]
    assert set(dup["counters_moved"]) <= set(dup["health_diff"])
    assert doc["all_recovered"] == all(r["checks"]["recovered"] for r in doc["cases"])


def test_reliability_table_and_missed_lines(short_reliability):
    doc, _ = short_reliability
    table = reliability.format_table(doc)
    for name, rate, _ in CASES:
        assert reliability.case_label(name, rate) in table
    missed = reliability.missed_targets(doc)
    assert len(missed) == sum(not r["checks"]["recovered"] for r in doc["cases"])
    assert all("not recovered" in line for line in missed)


def _row(steps=500, lost=0, pdr=5.0, fused=1.2, tail=30):
    return {
        "frames_sent": 100_000,
        "frames_lost": lost,
        "steps": steps,
        "steps_last_30s": tail,
        "primary_scheme": "adaptive",
        "mean_error_m": {"pdr_only": pdr, "adaptive": fused},
    }


@pytest.mark.parametrize(
    "row, recovered",
    [
        (_row(), True),
        (_row(steps=489), False),  # > 2 % fewer steps with < 2 % frames lost
        (_row(steps=400, lost=3000), True),  # 3 % lost: steps not checked
        (_row(pdr=8.6), False),  # > 1.5 x 5 + 1 m
        (_row(fused=2.7), True),  # <= 1.5 x 1.2 + 1 m
        (_row(fused=2.9), False),
        (_row(tail=0), False),  # no step in the last 30 s
    ],
)
def test_recovered_rule(row, recovered):
    assert reliability.recovered(row, _row())["recovered"] is recovered


def _stuck(offset_ms=0.0, matched=1000, err=1.2):
    return {
        **_row(),
        "fault": "board_time_stuck",
        "measures": {
            "imu_after_clean": 1000,
            "imu_after_matched": matched,
            "time_offset_after_max_ms": offset_ms,
            "mean_error_after_m": {"adaptive": {"case": err, "clean": 1.0}},
        },
    }


def _failed(pose=33_000, steps=0, wifi=62, clean_wifi=62, last=0.5):
    side = {"pose_messages": 30_000, "steps_after_grace": 0, "wifi_fixes_in_failure": clean_wifi}
    case = {
        "pose_messages": pose,
        "steps_after_grace": steps,
        "wifi_fixes_in_failure": wifi,
        "last_output_before_end_s": last,
    }
    # the common checks would fail (no steps, a large error): the fault's own replace them
    return {
        **_row(steps=250, pdr=40.0, tail=0),
        "fault": "imu_failed",
        "measures": {"case": case, "clean": side},
    }


@pytest.mark.parametrize(
    "row, recovered",
    [
        (_stuck(), True),
        (_stuck(offset_ms=9.9), True),
        (_stuck(offset_ms=57_451.0), False),  # output times shifted for the rest of the walk
        (_stuck(matched=800), False),  # samples after the fault missing
        (_stuck(err=2.6), False),  # > 1.5 x 1.0 + 1 m after the fault
        (_failed(), True),
        (_failed(pose=36_001), False),  # > 1.2 x the clean run's POSE messages
        (_failed(pose=179_910), False),  # a POSE for every refused sample
        (_failed(steps=3), False),  # steps from a failed IMU
        (_failed(wifi=20), False),  # the Wi-Fi fixes stopped too
        (_failed(wifi=0, clean_wifi=0), True),  # no site: no Wi-Fi fix to check
        (_failed(last=30.0), False),  # the log stopped before the walk's end
        (_failed(last=None), False),
    ],
)
def test_fault_specific_recovery_rules(row, recovered):
    assert reliability.recovered(row, _row())["recovered"] is recovered


def test_unknown_fault_kind_is_bad_usage(tmp_path, stridefixd, capsys):
    parser = argparse.ArgumentParser()
    bench_cli.add_parser(parser.add_subparsers())
    args = parser.parse_args(
        [
            "bench",
            "reliability",
            "--faults",
            "gremlins",
            "--stridefixd",
            str(stridefixd),
            "--out",
            str(tmp_path),
        ]
    )
    assert bench_cli.run(args) == 2
    assert "gremlins" in capsys.readouterr().err


def test_short_soak_accounts_for_every_event(stridefixd, tmp_path):
    """GIVEN a 72 s soak walk with three resets, corruption, duplicates, bursts and a silence WHEN
    streamed into stridefixd THEN every line was read, every accepted event is in the log, and the
    RSS figures are there."""
    doc = soak.run_soak(Firmware(stridefixd), tmp_path, hours=0.02, checkpoint_h=0.005)
    assert json.loads((tmp_path / "soak.json").read_text())["accounting"] == doc["accounting"]
    acc = doc["accounting"]
    assert acc["checks"] == {k: True for k in acc["checks"]}
    assert acc["frames_read_by_daemon"] == acc["frames_sent_by_sim"] > 15_000
    assert doc["sim_faults"]["resets"] == 3
    rss = doc["rss"]
    assert rss["vm_hwm_checkpoint_kb"] > 0 and rss["vm_hwm_end_kb"] >= rss["vm_hwm_checkpoint_kb"]
    assert "peak RSS" in soak.format_table(doc)
