"""The analyzer's view of CONTEXT (the multi-scheme controller): metrics.json's ``context`` section,
the console line, the report's event table, and the controller's pose as the primary scheme."""

from __future__ import annotations

from numpy.testing import assert_allclose
from stridefix import context_t, pose_t
from stridefix_analyzer.io.results import read_analyze_metrics
from stridefix_analyzer.scoring.context import context_summary, format_context_line, rule_name

S = 1_000_000


def make_context(t_us, rule, kind, building, floor, switched, text, context=0, prev=-1):
    m = context_t()
    m.t_us, m.rule, m.kind, m.building, m.floor = int(t_us), rule, kind, building, floor
    m.state = context_t.STATE_TRANSITION if rule == context_t.RULE_NEAR_PORT else context_t.STATE_IN_CONTEXT
    m.context, m.prev_context, m.switched, m.rule_text = context, prev, switched, text
    m.scheme, m.method, m.port, m.port_kind = pose_t.SCHEME_EKF, 1, -1, 0
    return m


#: outdoors from 1 s; near A's door at 4 s; in A floor 0 at 6 s (door rule)
CONTEXTS = [
    (1 * S, context_t.RULE_CLS_UNLIMITED, context_t.KIND_OUTDOOR, -1, 0, True, "cls: outdoor (GNSS 4 m)"),
    (4 * S, context_t.RULE_NEAR_PORT, context_t.KIND_OUTDOOR, -1, 0, False, "near port 0 (door)"),
    (6 * S, context_t.RULE_DOOR, context_t.KIND_FLOOR, 0, 0, True, "door: 5 of 5 steps, <A> floor 0"),
]


def _health(msg, t_us):
    h = msg.health(t_us, 99)
    h.gnss_on_s, h.wifi_on_s, h.ble_on_s = 6.0, 9.5, 9.5
    h.context_transitions, h.context_switches, h.context_recalibrations = 1, 2, 0
    return h


def test_context_summary_counts_times_and_radios():
    cols = {
        k: [c[i] for c in CONTEXTS]
        for i, k in enumerate(("t_us", "rule", "kind", "building", "floor", "switched", "rule_text"))
    }
    got = context_summary(cols, {"gnss_on_s": 6.0, "wifi_on_s": 9.5, "ble_on_s": 9.5}, end_us=10 * S)
    assert got["events"] == 3 and got["switches"] == 2
    assert got["events_by_rule"] == {"cls_unlimited": 1, "near_port": 1, "door": 1}
    assert got["switches_by_rule"] == {"cls_unlimited": 1, "door": 1}
    assert_allclose([got["time_in_context_s"][k] for k in ("outdoor", "building 0 floor 0")], [5.0, 4.0])
    assert got["radios_on_s"] == {"gnss": 6.0, "wifi": 9.5, "ble": 9.5}
    assert [(r["from"], r["to"]) for r in got["rows"]][-1] == ("outdoor", "building 0 floor 0")
    assert_allclose([r["t_s"] for r in got["rows"]], [0.0, 3.0, 5.0])
    assert context_summary(None, {}) is None
    assert "no CONTEXT" in format_context_line(None)
    assert rule_name(context_t.RULE_LEFT_PORT) == "left_port" and rule_name(99) == "rule_99"


def test_analyze_writes_context_and_controller_is_primary(
    write_log, straight_walk, msg, tmp_path, cli_main, capsys
):
    # GIVEN a log where the controller's pose (scheme 8) starts later than ekf's (fewer POSE) and
    # CONTEXT messages WHEN analysed THEN the controller is the primary scheme and metrics.json has
    # the context section; the report shows the events with their evidence
    t, x, y = straight_walk
    events = [("TRUTH", msg.truth(ti, xi, yi)) for ti, xi, yi in zip(t, x, y)]
    events += [("POSE", msg.pose(ti, xi, yi + 2.0, scheme=pose_t.SCHEME_EKF)) for ti, xi, yi in zip(t, x, y)]
    events += [
        ("POSE", msg.pose(ti, xi, yi + 0.5, scheme=pose_t.SCHEME_CONTROLLER))
        for ti, xi, yi in zip(t, x, y)
        if ti >= 2 * S
    ]
    events += [("CONTEXT", make_context(*c)) for c in CONTEXTS]
    events.append(("HEALTH", _health(msg, int(t[-1]))))
    log = write_log("ctl.lcmlog", events)
    out = tmp_path / "an"
    assert cli_main(["analyze", str(log), "--out", str(out)]) == 0
    console = capsys.readouterr().out
    assert (
        "context: 3 events, 2 switches (cls_unlimited 1, door 1); last context building 0 floor 0" in console
    )
    doc = read_analyze_metrics(out / "metrics.json")
    assert doc["primary_scheme"] == "controller"
    assert_allclose(doc["position_error_m"]["mean"], 0.5)
    assert doc["context"]["switches_by_rule"] == {"cls_unlimited": 1, "door": 1}
    assert doc["context"]["context_switches"] == 2
    assert_allclose(doc["context"]["time_in_context_s"]["building 0 floor 0"], (t[-1] - 6 * S) / 1e6)
    assert cli_main(["report", str(out)]) == 0
    page = (out / "report.html").read_text()
    assert "door: 5 of 5 steps, &lt;A&gt; floor 0" in page  # escaped evidence text
    assert "outdoor → building 0 floor 0" in page


def test_analyze_without_context_has_null_section(walk_logs, tmp_path, cli_main, capsys):
    fw, sim = walk_logs
    out = tmp_path / "an"
    assert cli_main(["analyze", str(fw), str(sim), "--out", str(out)]) == 0
    assert "context: no CONTEXT message" in capsys.readouterr().out
    doc = read_analyze_metrics(out / "metrics.json")
    assert doc["context"] is None and doc["primary_scheme"] == "adaptive"
    assert cli_main(["report", str(out)]) == 0
    assert "no CONTEXT message in the logs" in (out / "report.html").read_text()
