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
