"""io/results: the kinds of realbench's results.json and analyze's metrics.json, their round trip,
files written before the kinds, and the error for a file of another kind."""

import json
import math

import pytest
from stridefix_analyzer.io import results as rs
from stridefix_analyzer.scoring import compare
from stridefix_lab.bench import realdata


def _score(mean):
    stats = {"n": 3, "mean": mean, "median": mean, "p75": mean, "p90": mean, "p95": mean, "max": mean}
    return {**stats, "rmse": mean, "unscored": 0, "floor_hit_rate": 1.0, "ipin_score": mean, "iso18305": {}}


def _fusion_doc(label="site/F1", means=(1.0, 2.0)):
    """A small fusion results document, as realbench summary builds it (before the kind)."""
    rows = [
        {
            "walk": f"w{i}",
            "error": None,
            "fold": {"K": 0.4},
            "rotation_learned": True,
            "waypoints": 5,
            "steps_nosite": 9,
            "duration_s": 12.0,
            "floors": [0],
            "dir": f"/work/w{i}",
            "fixes": {"ekf": _score(m)},
            "true_start": {"pdr_only": _score(2 * m)},
            "references": {},
            "fix_sources": {},
        }
        for i, m in enumerate(means)
    ]
    pooled = {**_score(sum(means) / len(means)), "walks": len(means), "walks_mean_over_15m": 0}
    summary = {
        "schemes": {"ekf": pooled},
        "adaptive_vs_wifi_only_reduction_pct": math.nan,  # written as null
        "references": {},
        "loses_to_reference": [],
        "primary": {"scheme": "ekf", "follows": {}},
    }
    group = {"label": label, "walks": len(means), "ran": len(means), "failed": [], "summary": summary}
    group |= {"fold_errors": [], "fix_sources": {}, "constants": {}, "walk_rows": rows}
    return {
        "benchmark": "realbench fusion (leave one walk out)",
        "format": "msindoor",
        "inputs": ["data/F1"],
        "true_start": True,
        "groups": [group],
        "params": {"jobs": 2, "scheduler": "serial"},
        "stridefixd": {"path": "stridefixd", "version": "1"},
        "run_s": {"prepare": 1.0, "folds": 2.0, "total": 3.5},
    }


def _crowd_doc(label="site/F1"):
    summary = {"truth_map": {}, "crowd_map": {}, "ratio": {"wifi_only": 1.1}, "crowd_positions": {}}
    group = {"label": label, "paired": 1, "summary": summary, "walk_rows": []}
    return {
        "benchmark": rs.CROWD_MAP_BENCHMARK,
        "format": "msindoor",
        "groups": [group],
        "run_s": {"total": 1.0},
    }


def _metrics_doc(label="walk"):
    stats = {
        "n": 3,
        "nonfinite": 0,
        **{k: 1.5 for k in ("mean", "median", "p75", "p90", "p95", "max", "rmse")},
    }
    scheme = {"n_pose": 10, "position_error_m": stats, "ipin_score": 2.0, "floor_hit_rate": 1.0}
    return {"label": label, "primary_scheme": "ekf", "position_error_m": stats, "per_scheme": {"ekf": scheme}}


def _write_plain(path, doc):
    """A file as written before the kinds: the document alone."""
    path.write_text(json.dumps(doc, allow_nan=True))
    return path


WRITERS = {
    rs.REALBENCH_RESULTS_KIND: (rs.write_realbench_results, rs.read_realbench_results, _fusion_doc),
    rs.CROWD_MAP_RESULTS_KIND: (rs.write_crowd_map_results, rs.read_crowd_map_results, _crowd_doc),
    rs.ANALYZE_METRICS_KIND: (rs.write_analyze_metrics, rs.read_analyze_metrics, _metrics_doc),
}


@pytest.mark.parametrize("kind", list(WRITERS))
def test_round_trip_stamps_the_kind_first_and_keeps_the_rest(tmp_path, kind):
    write, read, make = WRITERS[kind]
    doc = make()
    path = tmp_path / "out.json"
    written = write(path, doc)
    text = path.read_text()
    assert text.endswith("\n") and "NaN" not in text
    back = read(path)
    assert back == written and next(iter(back)) == "kind" and back["kind"] == kind
    # apart from the kind, exactly the document (non-finite numbers as null)
    plain = json.loads(json.dumps(doc, allow_nan=True).replace("NaN", "null"))
    assert {k: v for k, v in back.items() if k != "kind"} == plain
    assert list(back)[1:] == list(plain)
    assert rs.read_any_results(path).kind == kind


def test_writing_twice_keeps_one_kind(tmp_path):
    doc = rs.write_analyze_metrics(tmp_path / "a.json", _metrics_doc())
    again = rs.write_analyze_metrics(tmp_path / "b.json", doc)
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()
    assert list(again).count("kind") == 1


@pytest.mark.parametrize("kind", list(WRITERS))
def test_a_file_without_kind_is_read_as_v1(tmp_path, kind):
    _, read, make = WRITERS[kind]
    path = _write_plain(tmp_path / "old.json", make())
    doc = read(path)
    assert "kind" not in doc and doc == json.loads(path.read_text())
    anyr = rs.read_any_results(path)
    assert anyr.kind == kind
    assert [anyr.realbench is not None, anyr.crowd_map is not None, anyr.metrics is not None] == [
        k == kind for k in WRITERS
    ]


def test_another_kind_is_refused_naming_the_file_and_what_was_expected(tmp_path):
    path = tmp_path / "metrics.json"
    rs.write_analyze_metrics(path, _metrics_doc())
    with pytest.raises(rs.ResultsFileError) as err:
        rs.read_realbench_results(path)
    text = str(err.value)
    assert str(path) in text
    assert "'stridefix.analyze.metrics/v1'" in text and "expected 'stridefix.realbench.results/v1'" in text


@pytest.mark.parametrize(
    "kind", ["stridefix.realbench.results/v2", "stridefix.crowd.models/v1", "something else"]
)
def test_unknown_or_newer_kind_is_refused(tmp_path, kind):
    path = tmp_path / "results.json"
    path.write_text(json.dumps({"kind": kind, **_fusion_doc()}))
    with pytest.raises(
        rs.ResultsFileError, match=f"{path}: kind '{kind}'.*expected 'stridefix.realbench.results/v1'"
    ):
        rs.read_realbench_results(path)
    with pytest.raises(rs.ResultsFileError, match="expected one of"):
        rs.read_any_results(path)


def test_crowd_map_file_is_not_a_fusion_file(tmp_path):
    path = _write_plain(tmp_path / "crowd.json", _crowd_doc())
    with pytest.raises(rs.ResultsFileError, match="shaped as 'stridefix.realbench.crowd-map/v1'"):
        rs.read_realbench_results(path)


@pytest.mark.parametrize(
    ("text", "message"),
    [("[1, 2]", "not a result file"), ("{", "not JSON"), ('{"x": 1}', "no 'kind'")],
)
def test_unreadable_files_are_named(tmp_path, text, message):
    path = tmp_path / "x.json"
    path.write_text(text)
    with pytest.raises(rs.ResultsFileError, match=message) as err:
        rs.read_analyze_metrics(path)
    assert str(path) in str(err.value)
    with pytest.raises(rs.ResultsFileError, match="cannot read"):
        rs.read_analyze_metrics(tmp_path / "gone.json")


def test_a_metrics_file_lacking_a_key_is_named(tmp_path):
    path = tmp_path / "metrics.json"
    doc = _metrics_doc()
    del doc["primary_scheme"]
    path.write_text(json.dumps({"kind": rs.ANALYZE_METRICS_KIND, **doc}))
    with pytest.raises(rs.ResultsFileError, match="without primary_scheme"):
        rs.read_analyze_metrics(path)


def test_walk_scores_by_start_mode():
    row = _fusion_doc()["groups"][0]["walk_rows"][0]
    assert rs.walk_scores(row, "fixes")["ekf"]["mean"] == 1.0
    assert rs.walk_scores(row, "true_start")["pdr_only"]["mean"] == 2.0
    del row["true_start"]
    assert rs.walk_scores(row, "true_start") == {}
    with pytest.raises(ValueError, match="start mode"):
        rs.walk_scores(row, "sideways")


def test_compare_reads_new_and_old_files_and_refuses_another_kind(tmp_path, cli_main, capsys):
    new = tmp_path / "new.json"
    rs.write_realbench_results(new, _fusion_doc())
    old = _write_plain(tmp_path / "old.json", _fusion_doc())
    assert compare.load_run(str(new)) == compare.load_run(str(old))
    assert compare.load_run(str(new))[("site/F1", "w1")]["ekf"]["mean"] == 2.0
    models = tmp_path / "models.json"
    models.write_text(json.dumps({"kind": "stridefix.crowd.models/v1", "groups": []}))
    assert cli_main(["compare", str(models), str(new)]) == 2
    err = capsys.readouterr().err
    assert str(models) in err and "stridefix.crowd.models/v1" in err
    crowd = tmp_path / "crowd.json"
    rs.write_crowd_map_results(crowd, _crowd_doc())
    with pytest.raises(compare.CompareInputError, match="crowd-map"):
        compare.load_run(str(crowd))


def test_report_refuses_a_metrics_file_of_another_kind(tmp_path, cli_main, capsys):
    rs.write_realbench_results(tmp_path / "metrics.json", _fusion_doc())
    (tmp_path / "analysis.npz").write_bytes(b"")
    assert cli_main(["report", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "metrics.json" in err and "expected 'stridefix.analyze.metrics/v1'" in err


def test_bench_targets_read_fusion_and_crowd_map_files_with_and_without_kind(tmp_path):
    fusion_new = tmp_path / "fusion.json"
    rs.write_realbench_results(fusion_new, _fusion_doc("site1/F2"))
    crowd_old = _write_plain(tmp_path / "crowd.json", _crowd_doc("site1/F2"))
    groups = realdata.load_groups([fusion_new, crowd_old])
    g = groups["site1/F2"]
    assert g["run_s_total"] == 3.5 and g["crowd_map"]["paired"] == 1
    assert g["summary"]["schemes"]["ekf"]["mean"] == 1.5
    metrics = tmp_path / "metrics.json"
    rs.write_analyze_metrics(metrics, _metrics_doc())
    with pytest.raises(realdata.ResultsError, match="not a realbench results file"):
        realdata.load_groups([metrics])
