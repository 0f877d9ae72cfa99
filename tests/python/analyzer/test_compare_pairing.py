"""stridefix compare says how it paired the walks: two analyze metrics.json (one walk each) are the pair
whatever their --label; realbench results pair by (group, walk), and when nothing pairs the command
exits 3 naming what each side has."""

from __future__ import annotations

import json

import pytest
from stridefix_analyzer.scoring import compare


def _metrics(tmp_path, name, label, mean_m):
    """An analyze metrics.json of one walk labelled ``label`` (scheme adaptive)."""
    doc = {
        "kind": "stridefix.analyze.metrics/v1",
        "label": label,
        "primary_scheme": "adaptive",
        "position_error_m": {"mean": mean_m, "median": mean_m},
        "per_scheme": {
            "adaptive": {
                "position_error_m": {"mean": mean_m, "median": mean_m},
                "ipin_score": 2 * mean_m,
                "floor_hit_rate": 1.0,
            }
        },
    }
    path = tmp_path / name / "metrics.json"
    path.parent.mkdir()
    path.write_text(json.dumps(doc))
    return str(path)


def _results(tmp_path, name, group, walks):
    doc = {
        "groups": [
            {
                "label": group,
                "walk_rows": [
                    {"walk": w, "error": None, "fixes": {"adaptive": {"mean": 3.0}}} for w in walks
                ],
            }
        ]
    }
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(doc))
    return str(path)


def test_two_single_walk_metrics_pair_regardless_of_label(tmp_path, cli_main, capsys):
    # GIVEN two analyses of one walk with different labels (a baseline and a what-if)
    a = _metrics(tmp_path, "a", "baseline", 4.0)
    b = _metrics(tmp_path, "b", "with fingerprint.k=1", 3.0)
    # WHEN compared
    js = tmp_path / "c.json"
    assert cli_main(["compare", a, b, "--json", str(js)]) == 0
    out = capsys.readouterr().out
    # THEN they are the pair, the console says so naming both labels, and B − A is their difference
    assert "regardless of label" in out and "'baseline'" in out and "'with fingerprint.k=1'" in out
    row = json.loads(js.read_text())["schemes"][0]
    assert row["walks"] == 1 and row["diff_mean"] == pytest.approx(-1.0)


def test_realbench_runs_say_how_many_walks_paired(tmp_path, cli_main, capsys):
    a = _results(tmp_path, "a", "site1/F2", ["w1", "w2", "w3"])
    b = _results(tmp_path, "b", "site1/F2", ["w2", "w3", "w4"])
    assert cli_main(["compare", a, b]) == 0
    assert "paired 2 walk(s) by (group, walk): 3 in A, 3 in B" in capsys.readouterr().out


def test_nothing_paired_exits_3_and_shows_both_sides(tmp_path, cli_main, capsys):
    # GIVEN a realbench run and an analysis of a walk it does not hold
    a = _results(tmp_path, "a", "site1/F2", ["w1", "w2"])
    b = _metrics(tmp_path, "b", "my walk", 3.0)
    # WHEN compared THEN exit 3 with one error line naming the groups and walks of each side
    assert cli_main(["compare", a, b]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no walk pairs" in err[0]
    assert (
        "group 'site1/F2': 2 walk(s) 'w1', 'w2'" in err[0] and "group 'walk': 1 walk(s) 'my walk'" in err[0]
    )


def test_pair_runs_keeps_a_label_pair_when_labels_agree(tmp_path):
    a = compare.load_run(_metrics(tmp_path, "a", "same", 4.0))
    b = compare.load_run(_metrics(tmp_path, "b", "same", 5.0))
    pa, pb, note = compare.pair_runs(a, b, "A", "B")
    assert pa == a and pb == b and "'same'" in note and "regardless" not in note
