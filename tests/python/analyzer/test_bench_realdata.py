"""bench real-targets: issue 11's targets read from realbench results files, misses named."""

from __future__ import annotations

import json
import math

import pytest
from stridefix_analyzer.bench import realdata


def _doc(label: str, ekf_mean: float, floor_hit: float) -> dict:
    schemes = {"ekf": {"mean": ekf_mean, "p75": ekf_mean + 1.0, "ipin_score": ekf_mean + 1.0}}
    return {
        "groups": [
            {
                "label": label,
                "summary": {"schemes": schemes},
                "summary_true_start": {"schemes": {"pdr_only": {"mean": 5.0}}},
                "walk_rows": [
                    {
                        "walk": "IPIN2023_T3_TrainingTrial51_repetition02",
                        "fixes": {"ekf": {"floor_hit_rate": floor_hit}},
                    }
                ],
            }
        ]
    }


def test_targets_met_missed_and_not_run(tmp_path):
    f2 = tmp_path / "f2.json"
    f2.write_text(json.dumps(_doc("site1/F2", 3.2, 1.0)))
    gsd = tmp_path / "gsd.json"
    gsd.write_text(json.dumps(_doc("gsd/building 100", 5.0, 0.9)))
    rows, missed = realdata.check(realdata.load_groups([f2, gsd]))
    by = {r["target"]: r for r in rows}
    assert (
        by["site1/F2 [first fix] ekf mean <= 3.5"]["met"]
        and by["site1/F2 [first fix] ekf mean <= 3.5"]["value"] == 3.2
    )
    assert by["site1/F2 [first fix] ekf p75 <= 4.5"]["met"]  # 4.2 m
    assert math.isnan(by["site2/F3 [first fix] ekf mean <= 10"]["value"])
    assert "realbench site2/F3 [first fix] ekf mean <= 10: not run" in missed
    assert by["gsd/building 100 [true start] pdr_only mean <= 6"]["met"]
    assert "realbench gsd/building 100 Trial51 [first fix] ekf floor_hit_rate >= 0.99: 0.9" in missed


def test_bad_file_is_named(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(realdata.ResultsError, match="bad.json"):
        realdata.load_groups([bad])
