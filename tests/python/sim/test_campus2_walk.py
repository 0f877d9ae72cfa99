"""The campus2 walk and survey (the multi-scheme controller's SIL campus): GIVEN the built-in ``campus2`` scenario, THEN the walk crosses
no wall, its truth visits outdoor → A floor 0 → 1 → 2 → 0 → outdoor → B floor 0 in that order, the
summary's transitions are exactly the truth's outline and floor changes (door: the crossing sample;
stairs: the end of the last flight, after the floor changed on the landing; elevator: the end of the
ride), the elevator rides have their wait, seeds change the walker and the noise but not the world,
and the ``campus2_survey`` covers every floor of A and B with Wi-Fi scans and BLE."""

from __future__ import annotations

import numpy as np
import pytest
from stridefix_sim.building import building_text
from stridefix_sim.pipeline import simulate
from stridefix_sim.radio import walls_crossed
from stridefix_sim.scenario import ScenarioError, builtin_scenario, parse_scenario
from stridefix_sim.transitions import context_track
from stridefix_sim.world_campus2 import ELEVATOR_WAIT_XY_M, WAIT_FLOOR1_S, WAIT_FLOOR2_S
from stridefix_sim.world_sources import inside

ORDER = [("outdoor", None, 0), ("floor", "A", 0), ("floor", "A", 1), ("floor", "A", 2)]
ORDER += [("floor", "A", 0), ("outdoor", None, 0), ("floor", "B", 0)]
KINDS = ["door", "stairs", "elevator", "elevator", "door", "door"]
STAIRS_AFTER_FLOOR_S = 15.0  # the landing and the second flight after the truth floor changes


@pytest.fixture(scope="module", params=[1, 2, 3])
def run(request):
    """The campus2 walk on one seed, simulated in-process."""
    return simulate(builtin_scenario("campus2").with_overrides(seed=request.param))


@pytest.fixture(scope="module")
def survey():
    return simulate(builtin_scenario("campus2_survey"))


def _runs(values) -> list:
    """Run-length: the values with consecutive repeats collapsed."""
    return [v for i, v in enumerate(values) if i == 0 or v != values[i - 1]]


def _riding(walk) -> np.ndarray:
    m = np.zeros(len(walk.t_s), bool)
    for ts, te, _dz, _i in walk.rides:
        m |= (walk.t_s >= ts) & (walk.t_s < te)
    return m


def test_walk_length_duration_and_no_wall_crossed(run):
    w = run.walk
    assert 300.0 <= w.s_m[-1] <= 450.0
    assert 250.0 <= run.duration_s <= 600.0
    assert walls_crossed(w.x_m[:-1], w.y_m[:-1], w.x_m[1:], w.y_m[1:], run.world.walls_m).sum() == 0
    # outdoors at the start and on the path between the buildings: GNSS fixes on both stretches
    out = ~inside(run.world.footprint_m, w.x_m, w.y_m)
    assert out[0] and not out[-1]
    ds = np.diff(w.s_m)
    assert float(np.sum(ds[out[1:] & out[:-1]])) >= 80.0
    g = run.sources.gnss
    indoor = inside(run.world.footprint_m, g.truth_x_m, g.truth_y_m)  # indoors only near a door
    door_d = np.min([np.hypot(g.truth_x_m - d.x_m, g.truth_y_m - d.y_m) for d in run.world.doors], axis=0)
    assert np.all(door_d[indoor] <= run.scenario["gnss"]["door_range_m"])
    assert ((g.truth_x_m > 40) & (g.truth_x_m < 80)).sum() >= 30  # the path between the buildings
    assert (g.t_ms < 1000 * float(w.t_s[np.argmin(out)])).sum() >= 15  # before entering A


def test_truth_visits_the_contexts_in_order(run):
    ctx = run.summary()["contexts"]
    track = context_track(run.world, run.walk)[~_riding(run.walk)]  # (a ride passes floor 1 on its way)
    got = [(ctx[i]["kind"], ctx[i]["building"], ctx[i]["floor"]) for i in _runs(track.tolist())]
    assert got == ORDER


def test_transitions_match_the_truth_changes(run):
    s = run.summary()
    w, tr = run.walk, s["transitions"]
    start_us = run.board_time_start_ms * 1000
    assert [t["kind"] for t in tr] == KINDS
    assert [t["port"] for t in tr] == ["A-door", "A-stairs", "A-elevator", "A-elevator", "A-door", "B-door"]
    assert all(a["to"] == b["from"] for a, b in zip(tr, tr[1:]))  # a chain of contexts
    assert all(t["t_us"] == start_us + round(t["t_s"] * 1e6) for t in tr)
    ctx = [(c["kind"], c["building"], c["floor"]) for c in s["contexts"]]
    assert [ctx[tr[0]["from"]]] + [ctx[t["to"]] for t in tr] == ORDER
    # door: exactly the samples at which the truth changes side of an outline
    ins = inside(run.world.footprint_m, w.x_m, w.y_m)
    crossing_t = w.t_s[np.flatnonzero(np.diff(ins.astype(int))) + 1]
    np.testing.assert_allclose([t["t_s"] for t in tr if t["kind"] == "door"], crossing_t, atol=1e-9)
    # the landmark is read as the door is crossed (the tag sits on the outline)
    lm = run.sources.landmarks
    assert [e.landmark_id for e in lm] == [1, 1, 2]
    np.testing.assert_allclose([e.t_ms / 1000 for e in lm], crossing_t, atol=0.02)
    # floor changes outside the rides: the staircase (floor 0 -> 1 at the landing), then the stairs
    # transition when the last flight ends, within STAIRS_AFTER_FLOOR_S
    fl, ride = w.floor, _riding(w)
    ch = np.flatnonzero(np.diff(fl)) + 1
    walked = [k for k in ch if not ride[k]]
    assert [(int(fl[k - 1]), int(fl[k])) for k in walked] == [(0, 1)]
    t_st = next(t for t in tr if t["kind"] == "stairs")["t_s"]
    assert 0.0 < t_st - w.t_s[walked[0]] <= STAIRS_AFTER_FLOOR_S
    k = int(round(t_st * 100))
    assert w.level_m[k] == pytest.approx(run.world.storey_m, abs=0.05)  # off the last stair (blend)
    assert np.all(w.step_mode[(w.step_t_s > t_st + 1.0) & (w.step_t_s < t_st + 10.0)] != 2)
    # elevator: at the end of each ride, from the floor where it started to the one where it stopped
    els = [t for t in tr if t["kind"] == "elevator"]
    assert len(els) == len(w.rides) == 2
    for t, (ts, te, dz, _i) in zip(els, w.rides):
        assert t["t_s"] == pytest.approx(te, abs=1e-6)
        a, b = int(fl[int(round(ts * 100)) - 1]), int(fl[int(round(te * 100)) + 1])
        assert (t["from_context"]["floor"], t["to_context"]["floor"]) == (a, b)
        assert dz == pytest.approx((b - a) * run.world.storey_m, abs=1e-6)


def test_elevator_wait_and_ride(run):
    w = run.walk
    near = np.hypot(w.x_m - ELEVATOR_WAIT_XY_M[0], w.y_m - ELEVATOR_WAIT_XY_M[1]) < 0.05
    still = near & (w.speed_mps < 1e-6)
    for (ts, te, _dz, _i), wait in zip(w.rides, (WAIT_FLOOR1_S, WAIT_FLOOR2_S)):
        before = still & (w.t_s < ts) & (w.t_s > ts - wait - 30.0)
        assert before.sum() / 100.0 >= wait - 0.05  # stood waiting for the cab
        assert 4.0 <= te - ts <= 15.0  # a few seconds per floor


def test_staircase_steps(run):
    w = run.walk
    on_stairs = int(np.sum(w.step_mode == 2))
    # one step per stair: 20 risers end to end; the first step onto a flight may still be a level one
    assert 16 <= on_stairs <= 22


def test_seeds_change_walker_and_noise_not_world():
    a = simulate(builtin_scenario("campus2"))
    b = simulate(builtin_scenario("campus2").with_overrides(seed=2))
    assert building_text(a.world) == building_text(b.world)
    assert a.walk.person.as_dict() != b.walk.person.as_dict()
    assert len(a.walk.step_t_s) != len(b.walk.step_t_s) or not np.allclose(a.walk.step_t_s, b.walk.step_t_s)
    assert a.board.lines != b.board.lines
    assert [t["port"] for t in a.summary()["transitions"]] == [t["port"] for t in b.summary()["transitions"]]


def test_survey_covers_every_floor_and_b(survey):
    w, world = survey.walk, survey.world
    a, b = world.outlines
    stops = w.stops
    on = {
        (o.name, f): [s for s in stops if o.holds(s["x_m"], s["y_m"]) and s["floor"] == f]
        for o in (a, b)
        for f in o.floors
    }
    assert all(len(v) >= 15 for v in on.values()), {k: len(v) for k, v in on.items()}
    assert len(stops) == len(world.survey_points_m)
    assert walls_crossed(w.x_m[:-1], w.y_m[:-1], w.x_m[1:], w.y_m[1:], world.walls_m).sum() == 0
    per = survey.summary()["scans_per_point"]
    assert all(p["scans"] == per for p in survey.summary()["survey_points"])
    # BLE is heard at every stop in B (what the site build learns B's constellation from); in A
    # only on floor 0 towards its door (through the doors' line, 60 m and more), at under 5 % of B's rate
    ads_s = survey.sources.ble.t_ms / 1000.0
    for s in on[("B", 0)]:
        assert np.sum((ads_s >= s["t_arrive"]) & (ads_s < s["t_leave"])) >= 10
    k = np.minimum(np.round(ads_s * 100).astype(int), len(w.x_m) - 1)
    in_a, in_b = a.holds(w.x_m[k], w.y_m[k]), b.holds(w.x_m[k], w.y_m[k])
    assert set(w.floor[k][in_a].tolist()) <= {0}
    t_a, t_b = a.holds(w.x_m, w.y_m).sum() / 100.0, b.holds(w.x_m, w.y_m).sum() / 100.0
    assert in_a.sum() / t_a < 0.05 * in_b.sum() / t_b
    # Wi-Fi: at stops in A the floor's own APs are the loudest
    for scan in survey.scans[:: max(1, len(survey.scans) // 200)]:
        i = int(round(scan.t_ms / 10))
        if not a.holds(w.x_m[i], w.y_m[i]) or not scan.aps:
            continue
        floor_of = {ap.bssid: ap.floor for ap in world.aps}
        loudest = max(scan.aps, key=lambda r: r[1])[0]
        assert floor_of[loudest] == w.floor[i]


def test_legs_route_needs_a_world_with_legs():
    with pytest.raises(ScenarioError, match="'legs': world 'default' has none"):
        parse_scenario('[walk]\nroute = "legs"\n')
