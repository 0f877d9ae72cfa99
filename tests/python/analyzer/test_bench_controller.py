"""bench controller's own figures on synthetic tables: the truth's context from building outlines, the
simulator's transitions, detection latency, false switches, per-context errors, the pooled table and
the issue's targets (met and missed, a missing controller is a miss)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import context_t
from stridefix_lab.bench import controller
from stridefix_lab.bench import controller_score as cs

#: two buildings: A a 30 × 20 m box at the origin, B an L-shaped hexagon east of it [m]
A = cs.Outline("A", np.array([[0, 0], [30, 0], [30, 20], [0, 20]], float))
B = cs.Outline("B", np.array([[80, 0], [100, 0], [100, 10], [90, 10], [90, 20], [80, 20]], float))
S = 1_000_000  # µs per s


def test_truth_contexts_outlines_and_floor():
    x = np.array([-1.0, 0.5, 15.0, 29.9, 50.0, 85.0, 95.0, 95.0])
    y = np.array([10.0, 10.0, 10.0, 19.9, 10.0, 15.0, 5.0, 15.0])  # (95, 15): in B's notch, outdoors
    floor = np.array([0, 0, 1, 2, 0, 0, 0, 0])
    assert cs.truth_contexts(x, y, floor, [A, B]).tolist() == [
        "outdoor", "A/0", "A/1", "A/2", "outdoor", "B/0", "B/0", "outdoor",
    ]  # fmt: skip


def test_context_holds_floor_and_building_contexts():
    assert cs.context_holds("A/1", "A/1") and not cs.context_holds("A/1", "A/2")
    assert cs.context_holds("A", "A/2") and not cs.context_holds("A", "AB/2")  # a building holds its floors
    assert cs.context_holds("outdoor", "outdoor") and not cs.context_holds("outdoor", "A/0")


def test_controller_keys_from_context_fields():
    kind = [0, context_t.KIND_OUTDOOR, context_t.KIND_FLOOR, context_t.KIND_BUILDING]
    assert cs.controller_keys(kind, [-1, -1, 1, 0], [0, 0, 2, 0], ["A", "B"]) == ["", "outdoor", "B/2", "A"]


def test_sim_transitions_indices_tables_and_seconds():
    summary = {
        "board_time_start_ms": 2000,
        "contexts": [
            {"kind": "outdoor", "building": None, "floor": 0},
            {"kind": "floor", "building": "A", "floor": 0},
            ["floor", "A", 1],
        ],
        "transitions": [
            {"kind": "stairs", "from": 1, "to": 2, "t_s": 50.5},
            {"kind": "door", "from": 0, "to": {"kind": "floor", "building": "A", "floor": 0}, "t_us": 12 * S},
        ],
    }
    got = cs.sim_transitions(summary)
    assert got == [
        cs.Transition(12 * S, "door", "outdoor", "A/0"),
        cs.Transition(2 * S + 50_500_000, "stairs", "A/0", "A/1"),
    ]
    with pytest.raises(cs.TransitionsError, match=r"transitions\[0\]\.to: context index 7"):
        cs.sim_transitions({"contexts": [], "transitions": [{"from": "outdoor", "to": 7, "t_us": 1}]})
    with pytest.raises(cs.TransitionsError, match="no 'transitions'"):
        cs.sim_transitions({})


def test_truth_transitions_from_a_timeline():
    t = np.arange(6) * S
    keys = np.array(["outdoor", "outdoor", "A/0", "A/0", "A/1", "A/1"], dtype=object)
    assert cs.truth_transitions(t, keys) == [
        cs.Transition(2 * S, "truth", "outdoor", "A/0"),
        cs.Transition(4 * S, "truth", "A/0", "A/1"),
    ]
    assert cs.timeline(t, keys) == [(0, 2 * S, "outdoor"), (2 * S, 4 * S, "A/0"), (4 * S, 5 * S, "A/1")]


TRANSITIONS = [
    cs.Transition(100 * S, "door", "outdoor", "A/0"),
    cs.Transition(200 * S, "stairs", "A/0", "A/1"),
    cs.Transition(300 * S, "elevator", "A/1", "A/2"),
]


def test_latency_early_late_missed():
    # the door detected 2 s late; the stairs 1.5 s early (within the tolerance); the elevator only
    # 31 s after (missed); a switch into the wrong floor near the elevator is no detection
    sw_t = np.array([102 * S, 198_500_000, 302 * S, 331 * S])
    sw_k = ["A/0", "A/1", "A/1", "A/2"]
    got = cs.latencies(TRANSITIONS, sw_t, sw_k)
    assert_allclose([g["latency_s"] for g in got[:2]], [2.0, -1.5])
    assert got[2]["latency_s"] is None and not got[2]["detected"]
    assert [g["within_target"] for g in got] == [True, True, False]
    # 6 s late is detected but not within the 5 s target; 6 s early is not this transition's switch
    got = cs.latencies(TRANSITIONS[:1], np.array([94 * S, 106 * S]), ["A/0", "A/0"])
    assert_allclose(got[0]["latency_s"], 6.0)
    assert got[0]["detected"] and not got[0]["within_target"]


def test_latency_window_stops_at_the_next_transition():
    # GIVEN a switch into A/1 after the walker already went on to A/2 WHEN scoring THEN the stairs
    # transition to A/1 is missed (that switch is not its detection)
    tr = [cs.Transition(100 * S, "stairs", "A/0", "A/1"), cs.Transition(110 * S, "stairs", "A/1", "A/2")]
    got = cs.latencies(tr, np.array([112 * S]), ["A/1"])
    assert got[0]["latency_s"] is None


def _truth(t_end_s=400):
    t = np.arange(0, t_end_s * 10) * (S // 10)
    keys = np.where(t < 100 * S, "outdoor", np.where(t < 200 * S, "A/0", np.where(t < 300 * S, "A/1", "A/2")))
    return t, keys.astype(object)


def test_false_switches_wrong_context_and_repeats():
    tt, tk = _truth()
    sw_t = np.array([1 * S, 103 * S, 150 * S, 160 * S, 203 * S, 297 * S])
    sw_k = ["outdoor", "A/0", "A/2", "A/0", "A/1", "A/2"]
    got = cs.false_switches(
        TRANSITIONS,
        sw_t,
        sw_k,
        tt,
        tk,
        ["cls_unlimited", "door", "elevator", "elevator", "stairs", "elevator"],
    )
    # the start, the door and the stairs are right; A/2 at 150 s is a wrong context; the switch back
    # to A/0 at 160 s follows no transition (the door's switch already did); 297 s is 3 s early: fine
    assert [g["why"] for g in got] == [None, None, "wrong context", "no transition", None, None]
    assert [g["false"] for g in got] == [False, False, True, True, False, False]
    assert got[2]["rule"] == "elevator"


def test_wrong_switch_does_not_use_up_the_transition():
    # GIVEN a wrong switch at the door then the right one WHEN scoring THEN only the first is false
    tt, tk = _truth()
    got = cs.false_switches(TRANSITIONS, np.array([101 * S, 104 * S]), ["A/1", "A/0"], tt, tk)
    assert [g["why"] for g in got] == ["wrong context", None]


def test_errors_by_context_finite_only():
    keys = np.array(["outdoor", "A/0", "A/0", "outdoor"], dtype=object)
    got = cs.errors_by_context(keys, np.array([1.0, 2.0, np.nan, 3.0]))
    assert got == {"A/0": [2.0], "outdoor": [1.0, 3.0], "whole walk": [1.0, 2.0, 3.0]}


def _walk(ctl_in_a, ctl_out, fixed_in_a=(3.0, 2.0), fixed_out=(1.0, 4.0), hits=(1, 1, 1, 1)):
    rows = {
        "controller": {
            "errors": {"A/0": list(ctl_in_a), "outdoor": list(ctl_out), "whole walk": [*ctl_in_a, *ctl_out]},
            "floor_hits": list(hits),
        }
    }
    for name, ea, eo in (("ekf", fixed_in_a[0], fixed_out[0]), ("particle", fixed_in_a[1], fixed_out[1])):
        rows[name] = {
            "errors": {"A/0": [ea, ea], "outdoor": [eo, eo], "whole walk": [ea, ea, eo, eo]},
            "floor_hits": [1, 1, 1, 1],
        }
    return {"rows": rows}


def _transitions(latencies):
    return [{"latency_s": v, "within_target": v is not None and v <= 5.0} for v in latencies]


def test_pool_and_targets_met():
    table = controller.pool([_walk([1.0, 1.0], [0.5, 0.5])])
    assert list(table) == ["controller", "ekf", "particle"]
    assert_allclose(table["controller"]["contexts"]["whole walk"]["mean_m"], 0.75)
    assert_allclose(table["ekf"]["contexts"]["A/0"]["mean_m"], 3.0)
    tg = controller.targets(table, _transitions([1.0, 4.9]), [{"false": False}], 1)
    assert all(t["met"] for t in tg), tg
    # whole walk: best fixed is ekf (2.0 m) → bound 1.6 m
    whole = next(t for t in tg if "whole walk" in t["figure"])
    assert "1.60 m" in whole["target"] and "ekf" in whole["target"]


def test_targets_missed():
    # controller worse than particle in A/0 (2.5 > 2.0), whole walk 1.75 > 0.8 × 2.0, a floor miss,
    # one late and one missed transition, a false switch
    table = controller.pool([_walk([2.5, 2.5], [1.0, 1.0], hits=(1, 1, 1, 0))])
    tg = {
        t["figure"]: t
        for t in controller.targets(table, _transitions([6.0, None, 1.0]), [{"false": True}], 1)
    }
    assert not tg["controller mean error in A/0"]["met"] and tg["controller mean error in outdoor"]["met"]
    assert not tg["controller mean error over the whole walk"]["met"]
    assert not tg["controller floor hit rate"]["met"] and tg["controller floor hit rate"]["value"] == 0.75
    late = tg["transitions detected within 5 s (3 transitions)"]
    assert not late["met"] and late["value"] == 1 and "1 missed" in late["target"]
    assert not tg["false switches in 1 seeds"]["met"]
    lines = controller.missed_targets({"targets": list(tg.values())})
    assert "controller: controller mean error in A/0 = 2.5 (target <= best fixed (particle: 2.00 m))" in lines


def test_no_controller_pose_misses_every_target():
    walk = _walk([1.0], [1.0])
    del walk["rows"]["controller"]
    tg = controller.targets(controller.pool([walk]), [], [], 1)
    assert tg and not any(t["met"] for t in tg)
