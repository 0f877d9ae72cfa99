"""Reports people read: a panel per floor over the site's walls, floor over time, error small
multiples, the configuration folded with enum names, CSV export and `stridefix compare`."""

import csv
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.stats import wilcoxon
from stridefix import pose_t
from stridefix_analyzer.firmware import Param
from stridefix_analyzer.io.sitefile import new_site, write_site
from stridefix_analyzer.scoring import compare, plots
from stridefix_analyzer.scoring.analyze import run_analyze
from stridefix_analyzer.scoring.config_table import config_html, enum_names


@pytest.fixture
def two_floor(msg, write_log, straight_walk, tmp_path):
    """Half the walk on floor 0, half on floor 1; adaptive 1 m off, pdr_only 3 m off and one floor low
    on the second half; a site with two walls on floor 0 and three on floor 1."""
    t, x, y = straight_walk
    n = len(t)
    floor = np.where(np.arange(n) < n // 2, 0, 1)
    events = [("CONFIG", msg.config({"floor.height_m": "3.5", "fingerprint.method": "1"}))]
    for i in range(n):
        events.append(("POSE", msg.pose(t[i], x[i], y[i] + 1.0, floor=int(floor[i]))))
        events.append(("POSE", msg.pose(t[i], x[i] + 3.0, y[i], floor=0, scheme=pose_t.SCHEME_PDR_ONLY)))
        events.append(("TRUTH", msg.truth(t[i], x[i], y[i], floor=int(floor[i]))))
    site = new_site(
        lowest_floor=0,
        floor_height_m=[0.0, 3.5],
        wall_x0_m=[0.0, 0.0, 0.0, 5.0, 10.0],
        wall_y0_m=[-2.0, 2.0, -2.0, -2.0, -2.0],
        wall_x1_m=[10.0, 10.0, 0.0, 5.0, 10.0],
        wall_y1_m=[-2.0, 2.0, 2.0, 2.0, 2.0],
        wall_floor=[0, 0, 1, 1, 1],
    )
    site_path = tmp_path / "s.sfsite"
    write_site(site_path, site)
    log = write_log("w.lcmlog", events)
    summary, metrics = run_analyze([str(log)], str(tmp_path / "an"), site=str(site_path))
    return summary, metrics, dict(np.load(tmp_path / "an" / "analysis.npz")), tmp_path


def test_trajectory_one_panel_per_floor_with_walls(two_floor):
    _, _, series, _ = two_floor
    assert list(series["site_wall_floor"]) == [0, 0, 1, 1, 1]
    fig = plots.plot_trajectory(series)
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title() for ax in panels] == ["floor 0 (walls: site)", "floor 1 (walls: site)"]
    for ax, n_walls in zip(panels, (2, 3)):
        walls = [ln for ln in ax.get_lines() if ln.get_color() == plots.style.WALL["color"]]
        assert len(walls) == n_walls
        truth = next(ln for ln in ax.get_lines() if ln.get_label() == "truth")
        on = np.isfinite(truth.get_xdata().astype(float))
        assert on.sum() == 50  # this floor's half of the walk only


def test_floor_over_time_and_error_small_multiples(two_floor):
    summary, _, series, _ = two_floor
    fig = plots.plot_floor_time(series)
    labels = {ln.get_label() for ln in fig.axes[0].get_lines()}
    assert {"truth", "adaptive", "pdr_only"} <= labels
    fig = plots.plot_error_time(series)
    assert len(fig.axes) == 2  # one panel per scheme, shared axes
    assert fig.axes[0].get_shared_y_axes().joined(fig.axes[0], fig.axes[1])
    assert "adaptive (primary)" in fig.axes[0].texts[0].get_text()
    assert summary["per_scheme"]["pdr_only"]["iso18305"]["vertical"]["mean_error_m"] == pytest.approx(1.75)


def test_config_folded_with_enum_names():
    table = {
        "fingerprint.method": Param(
            "fingerprint.method", "0", "", 0, 1, "0 = WkNN (Ramadhan 2016), 1 = Gaussian naive Bayes (Jaeger)"
        ),
        "fingerprint.k": Param("fingerprint.k", "3", "", 1, 16, "neighbours"),
        "floor.height_m": Param("floor.height_m", "3.5", "m", 1, 20, "height"),
    }
    assert enum_names(table["fingerprint.method"]) == {0: "WkNN", 1: "Gaussian naive Bayes"}
    assert enum_names(table["fingerprint.k"]) == {}  # 16 values: not an enum
    page = config_html(
        [("version", "1")], {"fingerprint.method": "1", "fingerprint.k": "3", "floor.height_m": "3.5"}, table
    )
    assert "1 differ from this stridefixd" in page
    assert "1 (Gaussian naive Bayes)" in page and "0 (WkNN)" in page
    assert page.count("<details>") == 2  # sections fingerprint and floor, folded


def test_config_enum_names_of_the_real_table(stridefixd):
    from stridefix_analyzer.firmware import Firmware

    params = Firmware(stridefixd).params
    assert enum_names(params["fingerprint.method"]) == {0: "WkNN", 1: "Gaussian naive Bayes"}
    assert enum_names(params["steps.detector"])[0] == "Pan-Tompkins"


def test_csv_export_round_trips(two_floor):
    from stridefix_analyzer.io.pose_csv import write_csv

    _, metrics, _, tmp_path = two_floor
    paths = write_csv(metrics, tmp_path / "csv")
    assert set(paths) == {"adaptive", "adaptive_matched", "pdr_only", "pdr_only_matched", "truth"}
    with open(paths["pdr_only_matched"], newline="") as f:
        rows = list(csv.DictReader(f))
    m = metrics.schemes[pose_t.SCHEME_PDR_ONLY].match
    assert_allclose([float(r["error_m"]) for r in rows], m["error_m"], rtol=0, atol=0)
    with open(paths["adaptive"], newline="") as f:
        rows = list(csv.DictReader(f))
    pose = metrics.schemes[pose_t.SCHEME_ADAPTIVE].pose
    assert len(rows) == len(pose) and [int(r["floor"]) for r in rows] == list(pose["floor"])
    assert float(rows[3]["t_s"]) == pose["t_us"][3] / 1e6


def _results(tmp_path, name, means):
    """A realbench results.json with one group and a walk row per mean (scheme adaptive)."""
    doc = {
        "groups": [
            {
                "label": "site/F1",
                "walk_rows": [
                    {"walk": f"w{i}", "error": None, "fixes": {"adaptive": {"mean": m, "ipin_score": 2 * m}}}
                    for i, m in enumerate(means)
                ],
            }
        ]
    }
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(doc))
    return str(path)


def test_compare_paired_walks_and_wilcoxon(tmp_path, cli_main, capsys):
    rng = np.random.default_rng(7)
    a = rng.uniform(3, 9, 12)
    b = a - rng.uniform(0.1, 1.0, 12)  # B better on every walk
    b[0] = a[0] + 0.5
    doc = compare.compare(
        compare.load_run(_results(tmp_path, "a", a)), compare.load_run(_results(tmp_path, "b", b))
    )
    r = doc["schemes"][0]
    assert r["walks"] == 12 and r["b_better"] == 11 and r["b_worse"] == 1
    assert_allclose(r["diff_mean"], np.mean(b - a), rtol=1e-12)
    assert_allclose(r["wilcoxon_p"], wilcoxon(b, a).pvalue, rtol=1e-12)
    assert r["wilcoxon_p"] < 0.01
    out, js = tmp_path / "c.html", tmp_path / "c.json"
    assert (
        cli_main(
            [
                "compare",
                _results(tmp_path, "a", a),
                _results(tmp_path, "b", b),
                "--out",
                str(out),
                "--json",
                str(js),
            ]
        )
        == 0
    )
    assert "adaptive" in capsys.readouterr().out
    assert "data:image/png;base64," in out.read_text()
    assert json.loads(js.read_text())["schemes"][0]["b_better"] == 11


def test_compare_few_walks_no_p_and_bad_input(tmp_path, cli_main, capsys):
    doc = compare.compare(
        compare.load_run(_results(tmp_path, "a", [1.0, 2.0, 3.0])),
        compare.load_run(_results(tmp_path, "b", [1.5, 2.0, 2.0])),
    )
    r = doc["schemes"][0]
    assert r["equal"] == 1 and np.isnan(r["wilcoxon_p"])
    (tmp_path / "x.json").write_text("[1, 2]")
    assert cli_main(["compare", str(tmp_path / "x.json"), str(tmp_path / "x.json")]) == 2
    assert "x.json" in capsys.readouterr().err


def test_compare_two_analyses(two_floor, cli_main, capsys):
    _, _, _, tmp_path = two_floor
    metrics_json = str(tmp_path / "an" / "metrics.json")
    assert cli_main(["compare", metrics_json, metrics_json, "--metric", "ipin_score"]) == 0
    out = capsys.readouterr().out
    assert "1 walks paired" in out and "pdr_only" in out
