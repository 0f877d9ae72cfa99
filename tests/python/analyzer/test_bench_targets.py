"""Exit status of `stridefix-lab bench`: 1 with a TARGET MISSED line per miss, 0 when every target is met.

On synthetic results only (a full benchmark takes minutes): the miss lines of each bench's JSON
document, and the command's exit status with the benchmark itself replaced.
"""

from __future__ import annotations

import argparse
import dataclasses
import json

import pytest
from stridefix_analyzer.firmware import Firmware
from stridefix_lab.bench import cli as bench_cli
from stridefix_lab.bench import fusion, sil_pdr


def _row(scenario="default", seed=1, step_error_pct=0.5, floor_hit_rate=1.0, final_error_pct=1.0):
    row = {
        "scenario": scenario,
        "seed": seed,
        "step_error_pct": step_error_pct,
        "floor_hit_rate": floor_hit_rate,
        "final_error_pct": final_error_pct,
    }
    row["targets"] = sil_pdr.meets_targets(row)
    return row


def test_sil_pdr_all_met_gives_no_line():
    assert sil_pdr.missed_targets({"runs": [_row(), _row(seed=2)]}) == []


def test_sil_pdr_names_figure_value_and_target():
    doc = {"runs": [_row(), _row("pace_fast", 3, step_error_pct=-1.5, floor_hit_rate=0.976)]}
    assert sil_pdr.missed_targets(doc) == [
        "sil-pdr pace_fast seed 3: step-count error = -1.5 % (target |error| <= 1.0 %)",
        "sil-pdr pace_fast seed 3: floor hit rate = 0.976 (target >= 0.99)",
    ]


def test_sil_pdr_unknown_value_is_not_a_miss():
    # a run with no floor truth has floor_hit_rate None: the target is not judged, not missed
    assert sil_pdr.missed_targets({"runs": [_row(floor_hit_rate=None)]}) == []


def _aadr(reduction, wifi=2.9, adaptive=1.7, kalman=1.6):
    table = {"wifi_only": {"mean_m": wifi}, "adaptive": {"mean_m": adaptive}, "kalman": {"mean_m": kalman}}
    return {
        "table": table,
        "adaptive_reduction_pct": reduction,
        "targets": {"adaptive_reduction_pct_min": 43.0, "kalman_at_least_as_good_as_adaptive": True},
        "targets_met": {
            "adaptive_reduction": reduction is not None and reduction >= 43.0,
            "kalman_vs_adaptive": kalman <= adaptive,
        },
    }


def test_aadr2015_lines():
    assert fusion.missed_targets_aadr2015(_aadr(45.0)) == []
    assert fusion.missed_targets_aadr2015(_aadr(38.21, kalman=1.8)) == [
        "aadr2015: adaptive's mean error reduction vs wifi_only = 38.21 % (target >= 43.0 %)",
        "aadr2015: kalman mean error = 1.80 m (target <= adaptive's 1.70 m)",
    ]
    assert "= n/a %" not in fusion.missed_targets_aadr2015(_aadr(None))[0]
    assert "= n/a (target" in fusion.missed_targets_aadr2015(_aadr(None))[0]


@pytest.mark.parametrize(
    "mean_m, p95_m, expected",
    [
        (1.5, 4.0, []),
        (2.31, 4.0, ["office-wifi: kalman mean error = 2.31 m (target <= 2.0 m)"]),
        (1.5, 5.0, ["office-wifi: kalman p95 error = 5.00 m (target <= 4.5 m)"]),
    ],
)
def test_office_lines(mean_m, p95_m, expected):
    doc = {
        "table": {"kalman": {"mean_m": mean_m, "p95_m": p95_m}},
        "targets": {"kalman_mean_m_max": 2.0, "kalman_p95_m_max": 4.5},
        "targets_met": {"kalman_mean": mean_m <= 2.0, "kalman_p95": p95_m <= 4.5},
    }
    assert fusion.missed_targets_office(doc) == expected


def test_exit_status_prints_target_missed_lines(capsys):
    assert bench_cli.exit_status([]) == 0
    assert capsys.readouterr().out == ""
    assert bench_cli.exit_status(["a = 1 (target <= 0)", "b"]) == 1
    assert capsys.readouterr().out == "TARGET MISSED: a = 1 (target <= 0)\nTARGET MISSED: b\n"


@pytest.fixture
def fake_firmware(tmp_path):
    """An executable file standing in for stridefixd (the bench itself is replaced)."""
    exe = tmp_path / "stridefixd"
    exe.write_text("#!/bin/sh\nexit 0\n")
    exe.chmod(0o755)
    return exe


@pytest.mark.parametrize("missed, status", [([], 0), (["x = 2 (target <= 1)"], 1)])
def test_bench_command_exit_status(monkeypatch, tmp_path, fake_firmware, capsys, missed, status):
    found = bench_cli.benches()
    found["sil-pdr"] = dataclasses.replace(found["sil-pdr"], run=lambda args, fw, seeds, out: list(missed))
    monkeypatch.setattr(bench_cli, "benches", lambda: found)
    parser = argparse.ArgumentParser()
    bench_cli.add_parser(parser.add_subparsers())
    args = parser.parse_args(["bench", "sil-pdr", "--stridefixd", str(fake_firmware), "--out", str(tmp_path)])
    assert bench_cli.run(args) == status
    assert ("TARGET MISSED: x = 2" in capsys.readouterr().out) == bool(missed)


def test_missing_firmware_is_bad_usage(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    bench_cli.add_parser(parser.add_subparsers())
    args = parser.parse_args(["bench", "sil-pdr", "--stridefixd", str(tmp_path / "nope")])
    assert bench_cli.run(args) == 2
    assert "stridefixd not found" in capsys.readouterr().err


def test_sil_pdr_writes_its_json_when_a_target_is_missed(monkeypatch, tmp_path, fake_firmware):
    # GIVEN a run that misses the final-error target WHEN the bench runs THEN the JSON is still
    # written, records the miss, and the miss becomes a TARGET MISSED line
    def fake_run_one(scenario, seed, firmware, out_dir, weinberg_k, sets=()):
        return _row(scenario, seed, final_error_pct=4.08)

    monkeypatch.setattr(sil_pdr, "run_one", fake_run_one)
    doc = sil_pdr.run_sil_pdr(["default"], [1], Firmware(fake_firmware), tmp_path, calibrate=False)
    written = json.loads((tmp_path / "sil_pdr.json").read_text())
    assert written["all_targets_met"] is False and doc["all_targets_met"] is False
    assert sil_pdr.missed_targets(written) == [
        "sil-pdr default seed 1: final error of distance walked = 4.08 % (target <= 2.0 %)"
    ]
