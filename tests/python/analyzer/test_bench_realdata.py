"""bench real-targets: the targets read from realbench results files, misses named."""

from __future__ import annotations

import json
import math

import pytest
from stridefix_lab.bench import realdata


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
    assert (
        "realbench gsd/building 100 Trial51 [first fix] ekf floor_hit_rate >= 0.99: 0.9 (bound 0.99)"
        in missed
    )


def test_bad_file_is_named(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(realdata.ResultsError, match="bad.json"):
        realdata.load_groups([bad])


def test_controller_bound_is_relative_to_the_best_fixed_scheme(tmp_path):
    """The controller target: the controller's mean within 2 % of the best fusion scheme of the same group."""
    doc = _doc("site1/F2", 3.0, 1.0)
    schemes = doc["groups"][0]["summary"]["schemes"]
    schemes["kalman"] = {"mean": 2.9}
    schemes["controller"] = {"mean": 2.95}  # itself never counts as the best
    path = tmp_path / "f2.json"
    path.write_text(json.dumps(doc))
    rows, missed = realdata.check(realdata.load_groups([path]))
    (row,) = [r for r in rows if r["target"].startswith("site1/F2 [first fix] controller mean")]
    assert row["bound"] == pytest.approx(1.02 * 2.9) and row["met"]
    schemes["controller"] = {"mean": 2.96}  # 2.958 is the bound
    path.write_text(json.dumps(doc))
    rows, missed = realdata.check(realdata.load_groups([path]))
    (row,) = [r for r in rows if r["target"].startswith("site1/F2 [first fix] controller mean")]
    assert not row["met"] and any("controller mean <= 1.02 x best fixed scheme: 2.96" in m for m in missed)


def test_crowd_map_bound_is_relative_to_the_truth_map(tmp_path):
    """The crowd-map target: the crowd-built map's Wi-Fi fix error within 15 % of the truth-built map's, read from
    a crowd-map results file beside (not instead of) the fusion results of the same group."""

    def crowd_doc(truth: float, crowd: float) -> dict:
        summary = {"truth_map": {"wifi_only": {"mean": truth}}, "crowd_map": {"wifi_only": {"mean": crowd}}}
        return {"benchmark": "crowd-map", "groups": [{"label": "site1/F2", "summary": summary}]}

    fusion = tmp_path / "fusion.json"
    fusion.write_text(json.dumps(_doc("site1/F2", 3.2, 1.0)))
    crowd = tmp_path / "crowd.json"
    crowd.write_text(json.dumps(crowd_doc(4.0, 4.5)))
    for order in ([fusion, crowd], [crowd, fusion]):  # either order: the fusion group is kept
        rows, missed = realdata.check(realdata.load_groups(order))
        by = {r["target"]: r for r in rows}
        row = by["site1/F2 [crowd map] wifi_only mean <= 1.15 x truth map"]
        assert row["value"] == 4.5 and row["bound"] == pytest.approx(4.6) and row["truth_map"] == 4.0
        assert row["met"] and by["site1/F2 [first fix] ekf mean <= 3.5"]["met"]
        assert "truth map 4" in realdata.format_table(rows)
    crowd.write_text(json.dumps(crowd_doc(4.0, 4.7)))
    rows, missed = realdata.check(realdata.load_groups([fusion, crowd]))
    assert any("[crowd map] wifi_only mean <= 1.15 x truth map: 4.7 (bound 4.6)" in m for m in missed)
    rows, missed = realdata.check(realdata.load_groups([fusion]))
    assert "realbench site1/F2 [crowd map] wifi_only mean <= 1.15 x truth map: not run" in missed


def test_wall_time_is_the_fusion_files_total_per_floor(tmp_path):
    """The speed budget: realbench <= 60 s per msindoor floor, read from the fusion file's run_s.total (a
    crowd-map file of the same group does not replace it); a file without it is not run."""
    doc = _doc("site1/F2", 3.2, 1.0)
    doc["run_s"] = {"prepare": 5.0, "folds": 40.0, "total": 47.5}
    fusion = tmp_path / "fusion.json"
    fusion.write_text(json.dumps(doc))
    crowd = tmp_path / "crowd.json"
    crowd.write_text(
        json.dumps({"benchmark": "crowd-map", "run_s": {"total": 500.0}, "groups": [{"label": "site1/F2"}]})
    )
    rows, missed = realdata.check(realdata.load_groups([fusion, crowd]))
    by = {r["target"]: r for r in rows}
    row = by["site1/F2 realbench fusion wall time [s] <= 60"]
    assert row["value"] == 47.5 and row["met"]
    assert "realbench site2/F3 realbench fusion wall time [s] <= 60: not run" in missed
    doc["run_s"]["total"] = 229.0
    fusion.write_text(json.dumps(doc))
    rows, missed = realdata.check(realdata.load_groups([crowd, fusion]))
    assert "realbench site1/F2 realbench fusion wall time [s] <= 60: 229 (bound 60)" in missed


def test_primary_every_fused_and_relative_targets():
    """The primary pose is the row summary.primary names; 'every fused scheme' holds the worst fused
    scheme (not pdr_only, wifi_only or the controller) to the bound; a bound relative to another row
    (a scheme or a textbook reference) is that row's value times the factor."""
    row = lambda ipin, floor=1.0: {"ipin_score": ipin, "floor_hit_rate": floor}  # noqa: E731
    summary = {
        "schemes": {
            "pdr_only": row(12.0, 0.5),
            "wifi_only": row(7.5, 0.9),
            "kalman": row(5.0),
            "ekf": row(6.0, 0.98),
            "controller": row(5.1),
        },
        "references": {"reference_ekf": row(5.2)},
        "primary": {"scheme": "controller", "follows": {"kalman": 3}},
    }
    groups = {realdata.IPIN2023: {"label": realdata.IPIN2023, "summary": summary}}
    targets = (
        realdata.Target(
            realdata.IPIN2023, "first fix", realdata.PRIMARY, "ipin_score", 1.0, relative_to="reference_ekf"
        ),
        realdata.Target(
            realdata.IPIN2023, "first fix", realdata.EVERY_FUSED, "ipin_score", 1.0, relative_to="wifi_only"
        ),
        realdata.Target(
            realdata.IPIN2023, "first fix", realdata.EVERY_FUSED, "floor_hit_rate", 0.99, at_least=True
        ),
    )
    rows, missed = realdata.check(groups, targets)
    assert [(r["value"], r["bound"], r["met"]) for r in rows] == [
        (5.1, 5.2, True),
        (6.0, 7.5, True),
        (0.98, 0.99, False),
    ]
    assert missed == [f"realbench {targets[2].describe()}: 0.98 (bound 0.99)"]
    assert "every fused scheme floor_hit_rate >= 0.99" in targets[2].describe()
    assert targets[0].describe().endswith("primary ipin_score <= 1 x reference_ekf")
