"""Which source each fix came from (scoring/fixsources.py): FIX records counted per scheme and method
with the generated fix_t names, pooled over walks, and shown by realbench's JSON, console and HTML."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from stridefix import fix_t, pose_t
from stridefix_analyzer import schemes
from stridefix_analyzer.radiomap.strides import spread
from stridefix_analyzer.scoring.fixsources import (
    METHOD_NAMES,
    REASON_NAMES,
    fix_source_counts,
    fix_sources_html,
    format_fix_sources,
    merge_fix_source_counts,
)
from stridefix_lab.realbench import report as rb_report
from stridefix_lab.realbench import summary as rb_summary
from stridefix_lab.realbench import tuning

KALMAN, ADAPTIVE = schemes.scheme_code("kalman"), schemes.scheme_code("adaptive")


def _fix_table(rows: list[tuple[int, int, bool, int]]) -> dict[str, np.ndarray]:
    """A FIX table of (scheme, method, accepted, reason) rows."""
    a = np.array(rows, dtype=np.int64).reshape(-1, 4)
    return {"scheme": a[:, 0], "method": a[:, 1], "accepted": a[:, 2].astype(bool), "reason": a[:, 3]}


def test_names_come_from_the_generated_constants():
    assert METHOD_NAMES[fix_t.METHOD_WIFI] == "wifi" and METHOD_NAMES[fix_t.METHOD_BLE] == "ble"
    assert METHOD_NAMES[fix_t.METHOD_GNSS] == "gnss" and METHOD_NAMES[fix_t.METHOD_LANDMARK] == "landmark"
    assert REASON_NAMES[fix_t.REASON_GATE] == "gate"
    n_methods = sum(1 for k in vars(fix_t) if k.startswith("METHOD_"))
    assert len(METHOD_NAMES) == n_methods


def test_counts_per_scheme_and_method():
    # GIVEN kalman: 3 Wi-Fi (2 accepted, 1 gated), 2 BLE (1 too few beacons, 1 gated), 1 landmark;
    # adaptive: 1 GNSS rejected as inaccurate
    acc, gate, few = fix_t.REASON_ACCEPTED, fix_t.REASON_GATE, fix_t.REASON_TOO_FEW_APS
    fix = _fix_table(
        [
            (KALMAN, fix_t.METHOD_WIFI, True, acc),
            (KALMAN, fix_t.METHOD_BLE, False, few),
            (KALMAN, fix_t.METHOD_WIFI, False, gate),
            (KALMAN, fix_t.METHOD_LANDMARK, True, acc),
            (KALMAN, fix_t.METHOD_WIFI, True, acc),
            (KALMAN, fix_t.METHOD_BLE, False, gate),
            (ADAPTIVE, fix_t.METHOD_GNSS, False, fix_t.REASON_INACCURATE),
        ]
    )
    c = fix_source_counts(fix)
    # THEN schemes in registry order, methods in fix_t order, reasons by name
    assert list(c) == [n for n in schemes.NAMES if n in ("kalman", "adaptive")]
    assert list(c["kalman"]) == ["wifi", "landmark", "ble"]
    assert c["kalman"]["wifi"] == {
        "offered": 3,
        "accepted": 2,
        "rejected": 1,
        "rejected_by_reason": {"gate": 1},
    }
    assert c["kalman"]["ble"] == {
        "offered": 2,
        "accepted": 0,
        "rejected": 2,
        "rejected_by_reason": {"too_few_aps": 1, "gate": 1},
    }
    assert c["adaptive"] == {
        "gnss": {"offered": 1, "accepted": 0, "rejected": 1, "rejected_by_reason": {"inaccurate": 1}}
    }
    assert fix_source_counts(None) == {} and fix_source_counts(_fix_table([])) == {}
    text = format_fix_sources(c)
    assert ["kalman", "BLE", "2", "0", "2", "gate", "1,", "too_few_aps", "1"] in [
        ln.split() for ln in text.splitlines()
    ]
    assert "<td>GNSS</td>" in fix_sources_html(c)
    assert format_fix_sources({}) == "fix sources: no FIX record"


def test_unknown_method_and_reason_ids_are_named_not_dropped():
    c = fix_source_counts(_fix_table([(KALMAN, 99, False, 77)]))
    assert c["kalman"]["method_99"]["rejected_by_reason"] == {"reason_77": 1}


def test_merge_pools_walks():
    a = fix_source_counts(_fix_table([(KALMAN, fix_t.METHOD_BLE, False, fix_t.REASON_GATE)]))
    b = fix_source_counts(
        _fix_table(
            [(KALMAN, fix_t.METHOD_BLE, True, 0), (KALMAN, fix_t.METHOD_BLE, False, fix_t.REASON_GATE)]
        )
    )
    m = merge_fix_source_counts([a, b, {}])
    assert m["kalman"]["ble"] == {
        "offered": 3,
        "accepted": 1,
        "rejected": 2,
        "rejected_by_reason": {"gate": 2},
    }
    assert a["kalman"]["ble"]["offered"] == 1  # the inputs are not changed


def test_realbench_pools_fix_sources_per_group_and_shows_them():
    # GIVEN two scored walks of one group, each with its FIX counts
    per_walk = [fix_source_counts(_fix_table([(KALMAN, fix_t.METHOD_GNSS, True, 0)] * n)) for n in (2, 3)]
    results = []
    for w, fs in zip(("walk_a", "walk_b"), per_walk, strict=True):
        row = {"mean": 1.0, "errors_m": [1.0], "floor_errors": [0]}
        results.append(
            {"walk": w, "group": "F2", "error": None, "fixes": {"kalman": row}, "fix_sources": {"fixes": fs}}
        )
    job_of = {
        r["walk"]: SimpleNamespace(
            index=i,
            rotation_learned=True,
            dir="/nonexistent",
            variants={},
            param_sets=[f"controller.init_scheme={pose_t.SCHEME_KALMAN}"],
        )
        for i, r in enumerate(results)
    }
    walks = [{"waypoint_t_us": [0], "step_t_us": [], "import": {}, "floors": [0]} for _ in results]
    info = {"F2": {"label": "F2", "walks": 2, "ran": 2, "failed": []}}
    # WHEN the document is built
    doc = rb_summary.build_doc("msindoor", [], ["F2"], info, walks, results, job_of, [], False)
    g = doc["groups"][0]
    # THEN the group pools them, each walk row keeps its own, the console and HTML show them
    assert g["fix_sources"]["kalman"]["gnss"]["offered"] == 5
    # without the controller the primary pose is the copy of controller.init_scheme's (its --set here)
    assert g["summary"]["primary"] == {"scheme": "kalman", "follows": {}}
    assert [r["fix_sources"]["kalman"]["gnss"]["accepted"] for r in g["walk_rows"]] == [2, 3]
    assert "fix_sources_true_start" not in g
    g["constants"] = {k: spread([1.0]) for k in ("K", "rotation_deg", "n_rp", "n_ap")}
    console = rb_summary.format_tables(doc, tuning.axes([]))
    assert "fix sources (FIX records per scheme and source, pooled over the walks):" in console
    assert ["kalman", "GNSS", "5", "5", "0", "-"] in [ln.split() for ln in console.splitlines()]
    assert "<td>GNSS</td><td>5</td><td>5</td>" in rb_report.render(doc)
