"""analyze sub-command: outputs, exit statuses."""

import numpy as np
from numpy.testing import assert_allclose
from stridefix_analyzer.io.results import ANALYZE_METRICS_KIND, read_analyze_metrics


def test_analyze_writes_metrics_and_series(walk_logs, tmp_path, cli_main, capsys):
    fw, sim = walk_logs
    out = tmp_path / "an"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out)]) == 0
    m = read_analyze_metrics(out / "metrics.json")
    assert next(iter(m)) == "kind" and m["kind"] == ANALYZE_METRICS_KIND
    for key in (
        "inputs",
        "position_error_m",
        "unscored",
        "floor_hit_rate",
        "steps",
        "distance_walked_m",
        "final_error_m",
        "final_error_pct_of_distance",
        "per_scheme",
        "messages",
        "health",
        "config",
    ):
        assert key in m, key
    # poses come 20 ms after their truth sample: the first truth sample is unscored, and each later
    # one is scored against the pose of the previous sample (0.1 m behind along x)
    assert m["unscored"] == 1 and m["position_error_m"]["n"] == 99
    assert_allclose(m["position_error_m"]["median"], np.hypot(0.1, 1.0), rtol=1e-9)
    assert_allclose(m["per_scheme"]["pdr_only"]["position_error_m"]["max"], 1.9, rtol=1e-9)
    assert m["steps"] == {"detected": 99, "step_messages": 0, "truth": 99, "error": 0, "error_pct": 0.0}
    assert m["messages"] == {"CONFIG": 1, "HEALTH": 1, "POSE": 200, "TRUTH": 100}
    assert m["health"]["frames_total"] == 99
    assert m["config"]["params"] == {"fusion.mode": "adaptive"}
    assert [i["events"] for i in m["inputs"]] == [202, 100]
    z = np.load(out / "analysis.npz")
    assert z["truth_x_m"].shape == z["error_m"].shape == (100,)
    assert np.isnan(z["error_m"][0]) and not z["scored"][0]
    assert_allclose(z["match_y_m"][1:], 1.0)
    assert_allclose(z["match_x_m"][1:], z["truth_x_m"][:-1])
    assert "adaptive" in capsys.readouterr().out


def test_analyze_scheme_option(walk_logs, tmp_path, cli_main):
    fw, sim = walk_logs
    out = tmp_path / "pdr"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out), "--scheme", "pdr_only"]) == 0
    m = read_analyze_metrics(out / "metrics.json")
    assert m["primary_scheme"] == "pdr_only"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out), "--scheme", "kalman"]) == 2


def test_missing_log_exits_2(tmp_path, cli_main, capsys):
    assert cli_main(["analyze", str(tmp_path / "gone.lcmlog"), "--out", str(tmp_path / "o")]) == 2
    assert "gone.lcmlog" in capsys.readouterr().err


def test_no_truth_describes_the_walk(msg, write_log, tmp_path, cli_main):
    # a field recording: no TRUTH, so nothing is scored, and the walk is described (test_walk.py)
    path = write_log("p.lcmlog", [("POSE", msg.pose(0, 0, 0))])
    assert cli_main(["analyze", str(path), "--out", str(tmp_path / "o")]) == 0
    m = read_analyze_metrics(tmp_path / "o" / "metrics.json")
    assert m["truth"] is False and m["primary_scheme"] == "adaptive" and "position_error_m" not in m


def test_no_pose_exits_2(msg, write_log, tmp_path, cli_main, capsys):
    path = write_log("t.lcmlog", [("TRUTH", msg.truth(0, 0, 0))])
    assert cli_main(["analyze", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "no POSE" in capsys.readouterr().err


def test_nothing_scored_exits_1(msg, write_log, tmp_path, cli_main):
    path = write_log("late.lcmlog", [("TRUTH", msg.truth(0, 0, 0)), ("POSE", msg.pose(5, 0, 0))])
    assert cli_main(["analyze", str(path), "--out", str(tmp_path / "o")]) == 1
    m = read_analyze_metrics(tmp_path / "o" / "metrics.json")
    assert m["position_error_m"]["n"] == 0 and m["position_error_m"]["mean"] is None


def test_analyze_json_and_console_carry_the_ipin_score(walk_logs, tmp_path, cli_main, capsys):
    # one floor throughout, so the IPIN score is the p75 of the 2-D error: adaptive is a constant
    # hypot(0.1, 1) m off (scored against the previous sample's pose), pdr_only 1.9 m
    fw, sim = walk_logs
    out = tmp_path / "ipin"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out)]) == 0
    m = read_analyze_metrics(out / "metrics.json")
    assert_allclose(m["per_scheme"]["adaptive"]["ipin_score"], np.hypot(0.1, 1.0), rtol=1e-9)
    assert_allclose(m["per_scheme"]["pdr_only"]["ipin_score"], 1.9, rtol=1e-9)
    assert m["ipin_score"] == m["per_scheme"][m["primary_scheme"]]["ipin_score"]
    console = capsys.readouterr().out
    assert "ipin" in console.splitlines()[0]
    assert cli_main(["report", str(out)]) == 0
    page = (out / "report.html").read_text()
    assert "IPIN score [m]" in page and f"{np.hypot(0.1, 1.0):.2f}" in page
