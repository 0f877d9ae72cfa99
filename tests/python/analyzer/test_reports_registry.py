"""Every report follows the scheme registry: a scheme added to pose_t.lcm shows up in analyze, the walk
report, realbench's console and HTML and the bench tables by itself; and realbench labels pdr_only's
truth-initialised row per data set.

The extra scheme is a fake: ``pose_t`` gets one more ``SCHEME_*`` constant (the next free id), and the
registry of :mod:`stridefix_analyzer.schemes` is rebuilt from it, as at import after an LCM change.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import pose_t
from stridefix_analyzer import schemes
from stridefix_analyzer.radiomap.strides import spread
from stridefix_analyzer.scoring import report as walk_report
from stridefix_analyzer.scoring.analyze import format_summary, run_analyze
from stridefix_lab.bench import fusion as bench_fusion
from stridefix_lab.realbench import report as rb_report
from stridefix_lab.realbench import summary as rb_summary
from stridefix_lab.realbench import tuning

FAKE = "fake_ekf"


@pytest.fixture
def one_more_scheme(monkeypatch):
    """The registry with one scheme more than pose_t.lcm defines (seven today): returns its names."""
    fake_id = max(s.id for s in schemes.SCHEMES) + 1
    monkeypatch.setattr(pose_t, f"SCHEME_{FAKE.upper()}", fake_id, raising=False)
    reg = schemes._from_lcm()
    monkeypatch.setattr(schemes, "SCHEMES", reg)
    monkeypatch.setattr(schemes, "NAMES", tuple(s.name for s in reg))
    monkeypatch.setattr(schemes, "_BY_ID", {s.id: s for s in reg})
    monkeypatch.setattr(schemes, "_BY_NAME", {s.name: s for s in reg})
    assert schemes.NAMES[-1] == FAKE and len(schemes.NAMES) >= 7
    return schemes.NAMES


def test_a_new_scheme_gets_its_own_colour(one_more_scheme):
    colours = [schemes.scheme_colour(s.id) for s in schemes.SCHEMES]
    assert len(set(colours)) == len(colours)


def test_analyze_and_walk_report_show_every_registered_scheme(
    one_more_scheme, msg, write_log, straight_walk, tmp_path
):
    # GIVEN a log with POSE of every registered scheme, scheme k offset k + 1 m from the truth
    t, x, y = straight_walk
    events = [("TRUTH", msg.truth(ti, xi, yi)) for ti, xi, yi in zip(t, x, y)]
    for k, s in enumerate(schemes.SCHEMES):
        events += [("POSE", msg.pose(ti, xi, yi + k + 1.0, scheme=s.id)) for ti, xi, yi in zip(t, x, y)]
    log = write_log("all.lcmlog", events)
    # WHEN it is analysed and reported
    summary, _ = run_analyze([str(log)], str(tmp_path / "an"))
    page = walk_report.render_html(*walk_report.load_analysis(str(tmp_path / "an")))
    console = format_summary(summary)
    # THEN every scheme has its row, its numbers and its IPIN score
    assert list(summary["per_scheme"]) == list(one_more_scheme)
    for k, name in enumerate(one_more_scheme):
        assert_allclose(summary["per_scheme"][name]["ipin_score"], k + 1.0, rtol=1e-12)
        assert name in console and f"<td class='k'>{name}</td>" in page


def _fake_results(names, true_start: bool) -> list[dict]:
    """Two walks of one group; scheme k errors (k + 1) m at its four samples, one floor off at one."""

    def row(k: int) -> dict:
        e = [k + 1.0] * 4
        return {"mean": k + 1.0, "errors_m": e, "floor_errors": [0, 0, 0, 1]}

    out = []
    for w in ("walk_a", "walk_b"):
        r = {"walk": w, "group": "F2", "error": None, "fixes": {n: row(k) for k, n in enumerate(names)}}
        if true_start:
            r["true_start"] = {n: row(k) for k, n in enumerate(names)}
        out.append(r)
    return out


def _doc(results: list[dict], fmt: str = "msindoor") -> dict:
    group = {
        "label": "F2",
        "walks": 2,
        "ran": 2,
        "failed": [],
        "fold_errors": [],
        "constants": {k: spread([1.0, 2.0]) for k in ("K", "rotation_deg", "n_rp", "n_ap")},
        "summary": rb_summary.summarize_group(results, "fixes"),
        "walk_rows": [
            {"walk": r["walk"], "waypoints": 4, "fold": {}, "dir": "/nonexistent", **r} for r in results
        ],
    }
    if "true_start" in results[0]:
        group["summary_true_start"] = rb_summary.summarize_group(results, "true_start")
    return {"format": fmt, "groups": [group]}


def test_realbench_console_and_html_show_every_registered_scheme(one_more_scheme):
    doc = _doc(_fake_results(one_more_scheme, true_start=True))
    table = doc["groups"][0]["summary"]["schemes"]
    assert list(table) == list(one_more_scheme)
    # pooled over both walks: 6 of 8 samples at k + 1 m, 2 at k + 16 m; Matlab's p75 halfway between the
    # 6th and 7th sorted values -> k + 1 + 7.5
    for k, name in enumerate(one_more_scheme):
        assert_allclose(table[name]["ipin_score"], k + 1.0 + 0.5 * 15.0, rtol=1e-12)
    console = rb_summary.format_tables(doc, tuning.axes([]))
    page = rb_report.render(doc)
    for name in one_more_scheme:
        assert f"  {name} " in console and f"<td>{name}</td>" in page


def test_realbench_labels_truth_initialised_pdr_per_data_set():
    for fmt in ("msindoor", "gsd"):
        doc = _doc(_fake_results(schemes.NAMES, true_start=True), fmt)
        console = rb_summary.format_tables(doc, tuning.axes([]))
        page = rb_report.render(doc)
        label = rb_summary.PDR_TRUE_START_LABEL
        assert label == "pdr_only (truth-initialised)"
        k = schemes.NAMES.index("pdr_only")
        # the row under the first-fix table, and the line naming the data set
        first_fix = console.split("[TRUTH-INITIALISED start]")[0]
        assert any(line.strip().startswith(label) for line in first_fix.splitlines())
        line = f"[{fmt}] F2: pdr_only from the TRUE START (truth-initialised): mean {k + 1.0:.2f} m"
        assert line in console and line in page
        assert f"<td>{label}</td>" in page and f"{label} mean" in page
    # without --true-start the line says it was not run, and there is no such row
    doc = _doc(_fake_results(schemes.NAMES, true_start=False))
    console = rb_summary.format_tables(doc, tuning.axes([]))
    assert "pdr_only from the TRUE START (truth-initialised): not run" in console
    assert rb_summary.PDR_TRUE_START_LABEL + " " not in console.split("TRUE START")[0]


def test_realbench_console_of_a_group_without_one_scored_walk():
    """Regression: a group whose walks all failed has no scheme row, and the table's width was
    max(10, *nothing) = TypeError; the header and the failed count are printed instead."""
    doc = _doc([{"walk": "walk_a", "group": "F2", "error": "import failed", "fixes": {}}])
    console = rb_summary.format_tables(doc, tuning.axes([]))
    assert "[every scheme from its first fix]" in console and "scheme" in console


def test_bench_tables_show_every_registered_scheme_with_ipin(one_more_scheme):
    # pdr_only last, then in id order; the IPIN score of (k + 1) m errors with one of four a floor off
    walk = {n: (np.full(4, k + 1.0), np.array([0, 0, 0, 1])) for k, n in enumerate(one_more_scheme)}
    table = bench_fusion.pooled_table({n: [v, v] for n, v in walk.items()})
    assert list(table) == [n for n in one_more_scheme if n != "pdr_only"] + ["pdr_only"]
    for k, name in enumerate(one_more_scheme):
        assert_allclose(table[name]["ipin_score_m"], k + 1.0 + 0.5 * 15.0, rtol=1e-12)  # as above
    text = bench_fusion.format_table(table, paper=True)
    assert FAKE in text and bench_fusion.PDR_ROW_LABEL in text and "ipin m" in text
    json.dumps(table)  # JSON-ready
    assert not any(math.isnan(r["ipin_score_m"]) for r in table.values())
