"""The map nobody surveyed: `stridefix crowd radiomap` (graph-solved positions → site) and
`stridefix-lab realbench crowd-map` (the fold sites of realbench fusion, truth-built vs crowd-built).

GIVEN three short SIL walkers (conftest ``sil_walks``) WHEN their radio map is built from positions solved
on the graph from every 4th truth point and their steps THEN it is a valid site whose reference points lie
near those of the truth-built one. GIVEN four real site1/F2 walks WHEN realbench crowd-map runs THEN every
fold is scored on both maps, the truth-map row is exactly realbench fusion's, and the crowd positions beat
the interpolated anchors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from stridefix_analyzer.io.results import (
    CROWD_MAP_RESULTS_KIND,
    read_crowd_map_results,
    read_realbench_results,
)
from stridefix_analyzer.io.sitefile import read_site
from stridefix_analyzer.radiomap.heading import HEADING_VARIANTS

MSINDOOR_F2 = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "msindoor" / "site1" / "F2"


def test_crowd_radiomap_site_near_the_truth_site(sil_walks, cli, tmp_path):
    crowd_path, truth_path = tmp_path / "crowd.sfsite", tmp_path / "truth.sfsite"
    proc = cli("crowd", "radiomap", *sil_walks, "--out", str(crowd_path), "--truth-site", str(truth_path))
    assert proc.returncode == 0, proc.stderr
    assert "anchors" in proc.stdout and "step rows" in proc.stdout
    rec = json.loads((tmp_path / "crowd.solve.json").read_text())
    assert rec["rows"]["anchors"] > 0 and rec["rows"]["steps"] > 2 * rec["rows"]["anchors"]
    assert rec["rows"]["wifi"] == 0
    g = rec["error"]["graph"]
    assert g["n"] > 0 and g["mean_m"] < 5.0  # dense SIL truth, anchors every 4th scan point
    crowd, truth = read_site(str(crowd_path)), read_site(str(truth_path))
    assert crowd.n_rp > 5 and truth.n_rp > 5 and crowd.n_ap > 0
    # every crowd reference point sits near a truth one: the same scans, positions off by the solve
    c = np.column_stack([crowd.rp_x_m, crowd.rp_y_m])
    t = np.column_stack([truth.rp_x_m, truth.rp_y_m])
    nearest = np.min(np.hypot(*(c[:, None, :] - t[None, :, :]).transpose(2, 0, 1)), axis=1)
    assert np.median(nearest) < 3.0 and np.mean(nearest) < 5.0
    assert 0.5 < crowd.n_rp / truth.n_rp < 2.0


@pytest.fixture(scope="module")
def crowd_map_small(request, tmp_path_factory, cli, lab) -> dict:
    """GIVEN realbench crowd-map and realbench fusion on the first 4 walks of site1/F2."""
    if not MSINDOOR_F2.is_dir():
        pytest.skip(
            f"real msindoor data not found at {MSINDOOR_F2} (needs ../shared/data beside the repository)"
        )
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("crowd_map")
    common = ["--format", "msindoor", str(MSINDOOR_F2), "--limit", "4", "--stridefixd", str(stridefixd)]
    common += ["--cache", str(out / "cache")]
    proc = lab("realbench", "crowd-map", *common, "--out", str(out / "crowd" / "results.json"))
    fusion = lab(
        "realbench", *common, "--quiet", "--no-report", "--out", str(out / "fusion" / "results.json")
    )
    assert fusion.returncode == 0, fusion.stderr
    return {
        "proc": proc,
        "doc": read_crowd_map_results(out / "crowd" / "results.json"),
        "fusion": read_realbench_results(out / "fusion" / "results.json"),
    }


def test_crowd_map_scores_both_maps(crowd_map_small):
    proc, doc = crowd_map_small["proc"], crowd_map_small["doc"]
    assert proc.returncode == 0, proc.stderr
    assert doc["benchmark"] == "crowd-map" and doc["anchors"] == "every:4"
    assert doc["kind"] == CROWD_MAP_RESULTS_KIND
    (g,) = doc["groups"]
    assert g["label"] == "site1/F2" and g["paired"] == 4 and len(g["walk_rows"]) == 4
    for row in g["walk_rows"]:
        assert row["error"] is None
        for m in ("truth_map", "crowd_map"):
            assert 0.0 < row[m]["wifi_only"]["mean"] < 50.0
            assert row["sites"][m]["n_rp"] > 0
        assert math.isclose(
            row["ratio"]["wifi_only"],
            row["crowd_map"]["wifi_only"]["mean"] / row["truth_map"]["wifi_only"]["mean"],
        )
        assert row["crowd_rows"]["anchors"] >= 1 and row["crowd_rows"]["wifi"] == 0
        # what the fold's crowd learned from its training walks' anchors: a real heading variant
        assert row["crowd_choice"]["heading_variant"] in HEADING_VARIANTS
        assert row["crowd_choice"]["priors"]["heading_sigma_rad"] > 0
    assert 1 <= doc["crowd_choices"] <= 4 and sum(g["crowd_heading_variants"].values()) == 4
    s = g["summary"]
    for scheme in ("wifi_only", "ekf"):
        assert 0.5 < s["ratio"][scheme] < 2.0  # generous: same walks, same protocol, nearby positions
    # the crowd positions (anchors + steps) are no worse than the anchors interpolated in time
    cp = s["crowd_positions"]
    assert cp["graph"]["n"] == cp["interpolated"]["n"] > 0
    assert cp["graph"]["mean_m"] < 1.2 * cp["interpolated"]["mean_m"]
    assert "pooled mean" in proc.stdout and "wifi_only truth" in proc.stdout


def test_truth_map_row_is_realbench_fusion(crowd_map_small):
    """The truth-built map is exactly the fold site realbench fusion builds: same per-walk scores."""
    (g,) = crowd_map_small["doc"]["groups"]
    (f,) = crowd_map_small["fusion"]["groups"]
    fusion = {r["walk"]: r["fixes"] for r in f["walk_rows"]}
    for row in g["walk_rows"]:
        for scheme in ("wifi_only", "ekf"):
            assert row["truth_map"][scheme]["mean"] == pytest.approx(
                fusion[row["walk"]][scheme]["mean"], abs=1e-9
            )
    assert g["summary"]["truth_map"]["wifi_only"]["mean"] == pytest.approx(
        f["summary"]["schemes"]["wifi_only"]["mean"], abs=1e-9
    )
