"""End to end: `stridefix crowd fit` + `crowd solve` + `crowd radiomap` on three short SIL walkers.

GIVEN three 60 s walkers of the office loop replayed through stridefixd (conftest ``sil_walks``)
WHEN the model is fitted on their scans and their positions are solved from every 4th scan point
THEN the model respects the bounds, the solve reports its solver and its error at the other points
is bounded, and the crowd radio map is a valid site file."""

from __future__ import annotations

import json

import pytest
from stridefix_analyzer.io.sitefile import read_site


@pytest.fixture(scope="module")
def fitted(sil_walks, cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("crowd_fit")
    proc = cli("crowd", "fit", *sil_walks, "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    return out, proc.stdout


def test_fit_writes_model_within_bounds_and_plot(fitted):
    out, stdout = fitted
    model = json.loads((out / "model.json").read_text())
    assert 0.0 <= model["floor_m"] <= model["min_distance_m"] + 1e-12
    assert model["intercept_m"] <= 0.0 and model["slope_m_per_db"] > 0.0
    assert model["n_pairs"] > 100 and model["rmse_m"] > 0 and model["r2"] <= 1.0
    assert "exact streaming binning" in model["method"]
    assert (out / "model_fit.png").stat().st_size > 1000
    assert "X3" in stdout


@pytest.mark.parametrize("ranges,bound_m", [("pdr", 3.0), ("both", 12.0)])
def test_solve_reports_solver_and_bounded_error(fitted, sil_walks, cli, tmp_path, ranges, bound_m):
    out, _ = fitted
    proc = cli(
        "crowd",
        "solve",
        *sil_walks,
        "--model",
        str(out / "model.json"),
        "--anchors",
        "every:4",
        "--ranges",
        ranges,
        "--out",
        str(tmp_path),
    )
    assert proc.returncode == 0, proc.stderr
    res = json.loads((tmp_path / "solve.json").read_text())
    assert res["solver"]["solver"].startswith(("stridefix_native", "scipy"))
    assert res["error"]["n"] > 20
    assert res["error"]["mean_m"] < bound_m
    assert (tmp_path / "positions.csv").read_text().count("\n") == res["problem"]["points"] + 1
    assert "solver" in proc.stdout


def test_crowd_radiomap_writes_sites(sil_walks, cli, tmp_path):
    proc = cli(
        "crowd",
        "radiomap",
        *sil_walks,
        "--out",
        str(tmp_path / "crowd.sfsite"),
        "--truth-site",
        str(tmp_path / "truth.sfsite"),
    )
    assert proc.returncode == 0, proc.stderr
    crowd, truth = read_site(str(tmp_path / "crowd.sfsite")), read_site(str(tmp_path / "truth.sfsite"))
    assert crowd.n_rp > 5 and truth.n_rp > 5 and crowd.n_ap > 0


def test_missing_model_is_a_usage_error(sil_walks, cli, tmp_path):
    proc = cli("crowd", "solve", *sil_walks, "--ranges", "wifi", "--out", str(tmp_path))
    assert proc.returncode == 2 and "model" in proc.stderr


def test_solve_default_is_the_graph_and_names_its_rows(sil_walks, cli, tmp_path):
    """GIVEN three SIL walkers WHEN crowd solve runs with its defaults THEN it solves the graph
    (steps + anchors every 4th scan point), says so with its row counts, and the error at the
    other scan points stays within a few metres."""
    proc = cli("crowd", "solve", *sil_walks, "--out", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "solve.json").read_text())
    rows = doc["problem"]["rows"]
    assert doc["problem"]["ranges"] == "graph" and rows["steps"] > 50 and rows["anchors"] > 10
    assert "step rows" in proc.stdout and "stride scales" in proc.stdout
    assert doc["error"]["n"] > 30 and doc["error"]["mean_m"] < 3.0
