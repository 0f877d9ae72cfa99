"""metrics: the evaluation protocol of DESIGN.md, checked against numbers known in advance."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import pose_t
from stridefix_analyzer.io.logread import Table, read_logs
from stridefix_analyzer.scoring.metrics import (
    IPIN_FLOOR_PENALTY_M,
    MetricsInputError,
    error_stats,
    ipin_score,
    run_metrics,
    scheme_code,
    step_metrics,
)

STATS = ("mean", "median", "p75", "p90", "p95", "max", "rmse")


def test_constant_one_metre_offset(msg, write_log, straight_walk):
    t, x, y = straight_walk
    events = []
    for ti, xi, yi in zip(t, x, y):
        events.append(("POSE", msg.pose(ti, xi, yi + 1.0)))  # published at the truth time
        events.append(("TRUTH", msg.truth(ti, xi, yi)))
    m = run_metrics(read_logs([write_log("w.lcmlog", events)])).summary()
    e = m["position_error_m"]
    assert e["n"] == 100 and m["unscored"] == 0
    assert_allclose([e[k] for k in STATS], 1.0, rtol=1e-12)
    assert_allclose(m["final_error_m"], 1.0, rtol=1e-12)
    assert_allclose(m["distance_walked_m"], 9.9, rtol=1e-12)
    assert_allclose(m["final_error_pct_of_distance"], 100 / 9.9, rtol=1e-12)
    assert m["floor_hit_rate"] == 1.0


def test_known_error_distribution_matches_numpy(msg, write_log):
    rng = np.random.default_rng(4)
    errors = rng.permutation(np.arange(1.0, 101.0))  # 1 … 100 m in a random order
    events = []
    for k, err in enumerate(errors):
        t = 1_000_000 + k * 200_000
        events.append(("POSE", msg.pose(t, 0.0, err)))
        events.append(("TRUTH", msg.truth(t + 50_000, 0.0, 0.0)))
    m = run_metrics(read_logs([write_log("d.lcmlog", events)]))
    e = m.summary()["position_error_m"]
    assert_allclose(e["median"], np.median(errors), rtol=1e-12)
    for p in (75, 90, 95):
        assert_allclose(e[f"p{p}"], np.percentile(errors, p), rtol=1e-12)
    assert_allclose(e["mean"], 50.5, rtol=1e-12)
    assert_allclose(e["max"], 100.0, rtol=1e-12)
    assert_allclose(e["rmse"], np.sqrt(np.mean(errors**2)), rtol=1e-12)
    assert_allclose(m.schemes[m.primary].match["error_m"], errors, rtol=1e-12)


def test_causal_latest_pose_at_or_before_truth(msg, write_log):
    events = [
        ("TRUTH", msg.truth(500_000, 0, 0)),  # before any pose: unscored
        ("POSE", msg.pose(1_000_000, 0, 0)),
        ("TRUTH", msg.truth(1_000_000, 0, 2)),  # pose at the same time counts: 2 m
        ("TRUTH", msg.truth(2_000_000, 0, 3)),  # still the 1 s pose: 3 m
        ("POSE", msg.pose(2_000_001, 0, 3)),  # 1 µs late: not used for t = 2 s
        ("TRUTH", msg.truth(3_000_000, 0, 7)),
    ]  # uses the 2.000001 s pose: 4 m
    m = run_metrics(read_logs([write_log("c.lcmlog", events)]))
    s = m.summary()
    assert s["unscored"] == 1 and s["position_error_m"]["n"] == 3
    err = m.schemes[m.primary].match["error_m"]
    assert np.isnan(err[0])
    assert_allclose(err[1:], [2.0, 3.0, 4.0], rtol=1e-12)
    assert_allclose(s["final_error_m"], 4.0)


def test_equal_time_poses_latest_published_wins(msg, write_log):
    events = [
        ("POSE", msg.pose(1_000, 50, 0)),
        ("POSE", msg.pose(1_000, 1, 0)),
        ("TRUTH", msg.truth(1_000, 0, 0)),
    ]
    m = run_metrics(read_logs([write_log("eq.lcmlog", events)]))
    assert_allclose(m.summary()["position_error_m"]["mean"], 1.0)


def test_floor_hit_rate(msg, write_log, straight_walk):
    t, x, y = straight_walk
    truth_floor = np.where(np.arange(100) < 60, 0, 1)  # pose stays on floor 0
    events = [("POSE", msg.pose(t[0], 0, 0, floor=0))]
    events += [("TRUTH", msg.truth(ti, xi, yi, floor=f)) for ti, xi, yi, f in zip(t, x, y, truth_floor)]
    s = run_metrics(read_logs([write_log("f.lcmlog", events)])).summary()
    assert_allclose(s["floor_hit_rate"], 0.6)
    assert s["floors_in_truth"] == [0, 1]


def test_step_count_error(msg, write_log, straight_walk):
    t, x, y = straight_walk
    truth_steps = list(range(100))
    truth_steps[-5:] = [-1] * 5  # unknown at the end: last known 94
    events = [("TRUTH", msg.truth(ti, xi, yi, step_count=s)) for ti, xi, yi, s in zip(t, x, y, truth_steps)]
    events += [
        ("POSE", msg.pose(ti, xi, yi, step_count=k * 90 // 99)) for k, (ti, xi, yi) in enumerate(zip(t, x, y))
    ]
    events += [("STEP", msg.step(ti, k + 1)) for k, ti in enumerate(t[:90])]
    s = run_metrics(read_logs([write_log("s.lcmlog", events)])).summary()["steps"]
    assert s["detected"] == 90 and s["truth"] == 94 and s["error"] == -4
    assert_allclose(s["error_pct"], -400 / 94)
    assert s["step_messages"] == 90


def test_step_metrics_without_pose_uses_step_messages():
    empty_pose = Table({"step_count": np.array([], dtype=np.int64)})
    truth = Table({"step_count": np.array([-1, 10, 20])})
    s = step_metrics(empty_pose, truth, n_step_messages=22)
    assert (s["detected"], s["truth"], s["error"]) == (22, 20, 2)
    assert_allclose(s["error_pct"], 10.0)
    s = step_metrics(empty_pose, Table({"step_count": np.array([-1, -1])}), 5)
    assert s["truth"] is None and s["error"] is None


def test_schemes_scored_separately(msg, write_log, straight_walk):
    t, x, y = straight_walk
    events = []
    for ti, xi, yi in zip(t, x, y):
        events.append(("POSE", msg.pose(ti, xi, yi + 1, scheme=pose_t.SCHEME_ADAPTIVE)))
        events.append(("POSE", msg.pose(ti, xi, yi - 3, scheme=pose_t.SCHEME_PDR_ONLY)))
        events.append(("POSE", msg.pose(ti, xi + 2, yi, scheme=pose_t.SCHEME_WIFI_ONLY)))
        events.append(("TRUTH", msg.truth(ti, xi, yi)))
    data = read_logs([write_log("m.lcmlog", events)])
    s = run_metrics(data).summary()
    assert set(s["per_scheme"]) == {"adaptive", "pdr_only", "wifi_only"}
    for name, expected in (("adaptive", 1.0), ("pdr_only", 3.0), ("wifi_only", 2.0)):
        e = s["per_scheme"][name]["position_error_m"]
        assert_allclose([e[k] for k in STATS], expected, rtol=1e-12)
        assert s["per_scheme"][name]["n_pose"] == 100
    assert s["primary_scheme"] == "adaptive"  # tie on counts: preference order
    assert_allclose(s["position_error_m"]["mean"], 1.0)
    s = run_metrics(data, scheme=scheme_code("pdr_only")).summary()
    assert s["primary_scheme"] == "pdr_only"
    assert_allclose(s["position_error_m"]["mean"], 3.0)
    with pytest.raises(MetricsInputError, match="kalman"):
        run_metrics(data, scheme=scheme_code("kalman"))


def test_scheme_first_pose_later_gives_its_own_unscored(msg, write_log):
    events = [
        ("POSE", msg.pose(0, 0, 0, scheme=pose_t.SCHEME_PDR_ONLY)),
        ("TRUTH", msg.truth(10, 0, 0)),
        ("POSE", msg.pose(15, 0, 0, scheme=pose_t.SCHEME_KALMAN)),
        ("TRUTH", msg.truth(20, 0, 0)),
    ]
    s = run_metrics(read_logs([write_log("u.lcmlog", events)])).summary()["per_scheme"]
    assert s["pdr_only"]["unscored"] == 0 and s["kalman"]["unscored"] == 1


@pytest.mark.parametrize("channels,missing", [(("POSE",), "TRUTH"), (("TRUTH",), "POSE")])
def test_missing_truth_or_pose_raises(msg, write_log, channels, missing):
    events = [(ch, msg.pose(0, 0, 0) if ch == "POSE" else msg.truth(0, 0, 0)) for ch in channels]
    with pytest.raises(MetricsInputError, match=f"no {missing}"):
        run_metrics(read_logs([write_log("x.lcmlog", events)]))


def test_error_stats_empty_and_nonfinite():
    s = error_stats(np.array([np.nan, 2.0, np.inf]))
    assert s["n"] == 1 and s["nonfinite"] == 2 and s["max"] == 2.0
    assert np.isnan(error_stats(np.array([]))["mean"])


def test_scheme_code_accepts_names_and_numbers():
    assert scheme_code("adaptive") == pose_t.SCHEME_ADAPTIVE
    assert scheme_code("5") == pose_t.SCHEME_KALMAN
    with pytest.raises(MetricsInputError, match="bogus"):
        scheme_code("bogus")


def test_heading_rms_error_wraps_at_pi(msg, write_log, straight_walk):
    """Pose heading 179° against truth −171° is a 10° error, not 350°; truth without heading
    (NaN) is left out of the heading statistics but still scored for position."""
    t, x, y = straight_walk
    events = []
    for k, (ti, xi, yi) in enumerate(zip(t, x, y)):
        pose = msg.pose(ti, xi, yi)
        pose.heading_rad = float(np.radians(179.0))
        truth_heading = float(np.radians(-171.0)) if k % 2 == 0 else float("nan")
        events += [("POSE", pose), ("TRUTH", msg.truth(ti, xi, yi, heading_rad=truth_heading))]
    m = run_metrics(read_logs([write_log("h.lcmlog", events)])).summary()
    assert m["heading_error"]["n"] == 50
    assert_allclose(m["heading_error"]["rms_deg"], 10.0, rtol=1e-4)
    assert_allclose(m["heading_error"]["mean_abs_deg"], 10.0, rtol=1e-4)
    assert m["position_error_m"]["n"] == 100


def test_truth_source_waypoint_scores_only_reference_points(msg, write_log, straight_walk):
    """10 Hz simulation truth plus a few WAYPOINT truths (the reference points of a walk): with
    truth_source='waypoint' only the reference points are scored."""
    from stridefix import truth_t

    t, x, y = straight_walk
    events = [("POSE", msg.pose(ti, xi, yi + 1.0)) for ti, xi, yi in zip(t, x, y)]
    events += [("TRUTH", msg.truth(ti, xi, yi)) for ti, xi, yi in zip(t, x, y)]
    for k in (10, 50, 90):
        wp = msg.truth(t[k], x[k], y[k] + 3.0)  # the reference points sit 3 m off: error 2 m
        wp.source = truth_t.SOURCE_WAYPOINT
        events.append(("TRUTH", wp))
    data = read_logs([write_log("wp.lcmlog", events)])
    all_truth = run_metrics(data).summary()
    assert all_truth["position_error_m"]["n"] == 103
    wp_only = run_metrics(data, truth_source="waypoint").summary()
    assert wp_only["position_error_m"]["n"] == 3
    assert_allclose(wp_only["position_error_m"]["mean"], 2.0, rtol=1e-12)
    with pytest.raises(MetricsInputError):
        run_metrics(data, truth_source="nonsense")


# --- the IPIN score ---------------------------------------------------------------------------------

# eight samples with 2-D errors 1..8 m; the last two one floor off (either sign): error + 15 m x |floor
# error| = 1, 2, 3, 4, 5, 6, 22, 23; Matlab's quantile puts the i-th of 8 at (i - 0.5)/8, so 0.75 falls
# halfway between the 6th (0.6875) and the 7th (0.8125): 6 + 0.5 x (22 - 6) = 14.0 m. Without the floor
# errors: 6 + 0.5 x 1 = 6.5 m.
IPIN_ERRORS_M = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
IPIN_FLOOR_ERRORS = [0, 0, 0, 0, 0, 0, 1, -1]


def test_ipin_score_of_a_handmade_series_is_the_formula():
    assert IPIN_FLOOR_PENALTY_M == 15.0
    assert_allclose(ipin_score(IPIN_ERRORS_M, IPIN_FLOOR_ERRORS), 14.0, rtol=1e-12)
    assert_allclose(ipin_score(IPIN_ERRORS_M, np.zeros(8)), 6.5, rtol=1e-12)
    # a non-finite sample is left out, not counted as zero: [1, 2, 3, 4, 22], 0.75 x 5 + 0.5 = 4.25th
    # value -> 4 + 0.25 x (22 - 4) = 8.5 m
    assert_allclose(ipin_score([1.0, 2.0, np.nan, 3.0, 4.0, 7.0], [0, 0, 0, 0, 0, 1]), 8.5, rtol=1e-12)
    assert np.isnan(ipin_score([], []))


def test_ipin_score_per_scheme_from_the_pose_stream(msg, write_log):
    # truth along x on floor 0; pdr_only 1..8 m ahead, on floor 1 for the last two samples
    events = []
    for k, (e_m, f) in enumerate(zip(IPIN_ERRORS_M, IPIN_FLOOR_ERRORS)):
        t = 1_000_000 * (k + 1)
        events.append(("POSE", msg.pose(t, k + e_m, 0.0, floor=abs(f), scheme=pose_t.SCHEME_PDR_ONLY)))
        events.append(("TRUTH", msg.truth(t, float(k), 0.0, floor=0)))
    m = run_metrics(read_logs([write_log("ipin.lcmlog", events)])).summary()
    assert_allclose(m["per_scheme"]["pdr_only"]["ipin_score"], 14.0, rtol=1e-12)
    assert_allclose(m["ipin_score"], 14.0, rtol=1e-12)  # the primary scheme's, at the top level
    assert_allclose(m["floor_hit_rate"], 0.75, rtol=1e-12)
