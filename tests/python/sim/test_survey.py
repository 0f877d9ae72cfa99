"""Survey mode and the aadr2015 foyer: calibration points get exactly 4 orientations x 3 scans while the
truth stands still on them; the foyer's geometry (Jäger, Süß, Becker); reference-point (WAYPOINT) truth;
the poor-coverage spot next to the magnetic disturbance; determinism; the old scenarios' bytes."""

from __future__ import annotations

import hashlib
import json
import math

import lcm
import numpy as np
import pytest
from stridefix import truth_t
from stridefix_sim.board import load_dbc, pack
from stridefix_sim.pipeline import simulate, write_truth_log
from stridefix_sim.route import Polyline
from stridefix_sim.scenario import BUILTIN, ScenarioError, builtin_scenario, parse_scenario
from stridefix_sim.world import survey_points
from stridefix_sim.world_aadr2015 import aadr2015_world

# sha256 of board.candump / truth.lcmlog of the built-in scenarios (seed 1) before survey mode existed
OLD_BYTES = {
    "default": (
        "a5c8a1bca3e22b037252c67bf2dedbd3e1694aca8484461999da9716a6e682ae",
        "3957dc6dd3c02d9a1a197a6a34eb243e63b53366260639e9a053d0882ae22de9",
    ),
    "pace_fast": (
        "85fb529557d80ca7dd3eb950ab6aeacb96b00086e5f2c6538efbadb688fa745e",
        "71db26128e42f3b8e6829157861217bee57f664c9b1a322f873773eacdf6a7cb",
    ),
}


def truth(out):
    return [truth_t.decode(ev.data) for ev in lcm.EventLog(str(out / "truth.lcmlog"), "r")]


def summary(out):
    return json.loads((out / "sim_summary.json").read_text())


def scans(out, candump, dbc):
    """Wi-Fi scans in the candump: [(board time at scan start [ms], [(bssid, rssi)], n_ap)]."""
    begin, ap, end = (dbc.get_message_by_name(n) for n in ("WIFI_SCAN_BEGIN", "WIFI_AP", "WIFI_SCAN_END"))
    out_scans, cur = [], None
    for _, can_id, data in candump(out / "board.candump"):
        if can_id == begin.frame_id:
            cur = (begin.decode(data)["time_ms"], [])
        elif can_id == ap.frame_id and cur is not None:
            d = ap.decode(data)
            cur[1].append((d["bssid"], d["rssi"]))
        elif can_id == end.frame_id and cur is not None:
            out_scans.append((cur[0], cur[1], end.decode(data)["n_ap"]))
            cur = None
    return out_scans


@pytest.fixture(scope="module")
def foyer_survey(sim_run):
    return sim_run("--scenario", "aadr2015_survey")


@pytest.fixture(scope="module")
def foyer_track(sim_run):
    return sim_run("--scenario", "aadr2015")


def test_survey_every_point_gets_4_orientations_x_3_scans_while_truth_stands_on_it(
    foyer_survey, candump, dbc
):
    s = summary(foyer_survey)
    assert s["n_points"] == 67 and s["scans_per_point"] == 12 and s["orientations"] == [0, 90, 180, 270]
    points = {(p["x_m"], p["y_m"], p["floor"]) for p in s["survey_points"]}
    assert len(points) == 67
    msgs = truth(foyer_survey)
    t_us = np.array([m.t_us for m in msgs])
    sc = scans(foyer_survey, candump, dbc)
    assert len(sc) == s["wifi_scans"] == 67 * 12
    per_point: dict = {}
    for t_ms, aps, n_ap in sc:
        assert n_ap == len(aps) > 0
        # every TRUTH from 100 ms before the scan starts to 100 ms after its results: one pose
        t0, t1 = t_ms * 1000 - 100_000, t_ms * 1000 + 120_000 + 100_000
        near = [msgs[i] for i in range(np.searchsorted(t_us, t0), np.searchsorted(t_us, t1, side="right"))]
        assert len(near) >= 3
        poses = {(m.x_m, m.y_m, m.floor) for m in near}
        headings = {round(m.heading_rad, 9) for m in near}
        assert len(poses) == 1 and len(headings) == 1, f"truth moves during the scan at {t_ms} ms"
        pose = poses.pop()
        assert pose in points
        facing = round(math.degrees(headings.pop())) % 360
        per_point.setdefault(pose, []).append(facing)
    assert set(per_point) == points
    for pose, facings in per_point.items():
        assert sorted(facings) == [0] * 3 + [90] * 3 + [180] * 3 + [270] * 3, pose


def test_survey_walks_between_points_and_stands_still_while_scanning(foyer_survey):
    s = summary(foyer_survey)
    assert s["route"] == "survey" and s["floors_visited"] == [0]
    assert s["activity_s"]["still"] > 0.7 * s["duration_s"]
    assert s["steps"] > 2 * 66 and 130 <= s["distance_m"] <= 200
    msgs = truth(foyer_survey)
    xy = np.array([[m.x_m, m.y_m] for m in msgs])
    assert np.max(np.hypot(*np.diff(xy, axis=0).T)) < 0.25  # walks, never jumps
    assert np.all((xy >= 0.5) & (xy <= [19.5, 13.5]))
    core = aadr2015_world().blocked_m[0]
    assert not np.any(
        (xy[:, 0] > core[0]) & (xy[:, 0] < core[2]) & (xy[:, 1] > core[1]) & (xy[:, 1] < core[3])
    )


def test_aadr2015_geometry():
    w = aadr2015_world()
    assert w.area_m2 == pytest.approx(280, abs=10) and w.n_floors == 1
    assert len(w.aps) == 8 and len({a.bssid for a in w.aps}) == 8
    pts = survey_points(w, 2.0, 0.5, [0], "world")
    assert len(pts) == 67
    assert np.allclose((pts[:, :2] - 1.0) % 2.0, 0.0)  # a 2 m grid
    assert np.array_equal(pts, survey_points(w, 2.0, 0.5, [0], "grid"))  # = the walkable-area grid
    for r in (0.8, 1.0):  # the corner radius depends on the pace
        assert 68.0 <= Polyline(w.track_m, r).length_m <= 72.0
    assert len(w.reference_points_m) == 14


def test_aadr2015_track_has_14_waypoint_truth_messages_in_order(foyer_track):
    s = summary(foyer_track)
    assert s["route"] == "track" and s["n_reference_points"] == 14
    assert s["world"]["name"] == "aadr2015" and s["world"]["n_aps"] == 8
    assert 68.0 <= s["distance_m"] <= 72.0
    msgs = truth(foyer_track)
    t = [m.t_us for m in msgs]
    assert t == sorted(t)
    sim = [m for m in msgs if m.source == truth_t.SOURCE_SIMULATION]
    wp = [m for m in msgs if m.source == truth_t.SOURCE_WAYPOINT]
    assert len(sim) == s["truth_messages"] and np.all(np.diff([m.t_us for m in sim]) == 100_000)
    assert len(wp) == 14
    refs = aadr2015_world().reference_points_m
    assert np.allclose([[m.x_m, m.y_m] for m in wp], refs)
    assert [(r["x_m"], r["y_m"]) for r in s["reference_points"]] == [tuple(p) for p in refs.tolist()]
    s_ref = [r["s_m"] for r in s["reference_points"]]
    assert all(b - a > 2.5 for a, b in zip(s_ref, s_ref[1:]))  # in order along the track
    # each waypoint lies on the 10 Hz truth path at its time (walking <= 2 m/s: 100 ms < 0.2 m)
    t_sim = np.array([m.t_us for m in sim])
    xy_sim = np.array([[m.x_m, m.y_m] for m in sim])
    for m in wp:
        x = np.interp(m.t_us, t_sim, xy_sim[:, 0])
        y = np.interp(m.t_us, t_sim, xy_sim[:, 1])
        assert math.hypot(x - m.x_m, y - m.y_m) < 0.03
        assert m.floor == 0 and m.step_count >= 0


def test_aadr2015_paces():
    for name, lo, hi in (("aadr2015_slow", 85, 110), ("aadr2015", 55, 75), ("aadr2015_fast", 40, 55)):
        sc = builtin_scenario(name)
        assert sc["world"]["name"] == "aadr2015" and sc["walk"]["route"] == "track"
        r = simulate(sc)
        assert lo <= r.duration_s <= hi, name
        assert len(r.reference_passes()) == 14


def test_poor_coverage_spot_hears_less(foyer_survey, candump, dbc):
    w = aadr2015_world()
    x0, y0, x1, y1 = w.poor_coverage_m
    msgs = truth(foyer_survey)
    t_us = np.array([m.t_us for m in msgs])
    inside_rssi, outside_rssi, inside_n, outside_n = [], [], [], []
    for t_ms, aps, _ in scans(foyer_survey, candump, dbc):
        m = msgs[np.searchsorted(t_us, t_ms * 1000, side="right") - 1]
        inside = x0 <= m.x_m <= x1 and y0 <= m.y_m <= y1
        (inside_rssi if inside else outside_rssi).extend(r for _, r in aps)
        (inside_n if inside else outside_n).append(sum(r > -70 for _, r in aps))
    assert len(inside_n) >= 4 * 12
    assert np.mean(inside_rssi) < np.mean(outside_rssi) - 8.0
    assert np.mean(inside_n) < np.mean(outside_n) - 2.0  # fewer usable APs


def test_magnetic_disturbance_next_to_the_poor_spot_and_on_the_track():
    w = aadr2015_world()
    x0, y0, x1, y1 = w.poor_coverage_m
    (zone,) = w.mag_zones
    gap = math.hypot(max(x0 - zone.x_m, 0, zone.x_m - x1), max(y0 - zone.y_m, 0, zone.y_m - y1))
    assert gap < 2.5  # next to it
    r = simulate(builtin_scenario("aadr2015"))
    wk = r.walk
    in_spot = (wk.x_m >= x0) & (wk.x_m <= x1) & (wk.y_m >= y0) & (wk.y_m <= y1)
    assert in_spot.sum() > 200  # the track crosses the spot (> 2 s)
    assert r.sensors.mag_zone_w.max() > 0.5  # and the disturbance
    field = np.linalg.norm(r.sensors.mag_ut - r.scenario["mag"]["hard_iron_ut"], axis=1)
    clean = r.sensors.mag_zone_w == 0
    assert abs(np.median(field[clean]) - 48.0) < 1.0
    assert field[r.sensors.mag_zone_w > 0.5].mean() > 55.0


def test_survey_and_track_are_deterministic(sim_run, foyer_survey, foyer_track):
    for out, argv in (
        (foyer_survey, ("--seed", "1", "--scenario", "aadr2015_survey")),
        (foyer_track, ("--seed", "1", "--scenario", "aadr2015")),
    ):
        again = sim_run(*argv)
        assert again != out
        for name in ("board.candump", "truth.lcmlog"):
            assert (again / name).read_bytes() == (out / name).read_bytes()
    other = sim_run("--scenario", "aadr2015", "--seed", "2")
    assert (other / "board.candump").read_bytes() != (foyer_track / "board.candump").read_bytes()


def test_office_survey_both_floors_small_grid(tmp_path, sim_cli, candump, dbc):
    """``--survey`` on the office, 8 m spacing to keep it short: both floors, the elevator between them."""
    f = tmp_path / "s.toml"
    f.write_text("[survey]\nspacing_m = 8.0\nscans_per_orientation = 2\n")
    out = tmp_path / "o"
    assert sim_cli(["--scenario", str(f), "--survey", "--out", str(out)]) == 0
    s = summary(out)
    assert s["route"] == "survey" and s["floors_visited"] == [0, 1] and s["elevator_rides"] == 1
    floors = [p["floor"] for p in s["survey_points"]]
    assert floors == sorted(floors) and set(floors) == {0, 1} and s["scans_per_point"] == 8
    msgs = truth(out)
    t_us = np.array([m.t_us for m in msgs])
    count: dict = {}
    for t_ms, _, _ in scans(out, candump, dbc):
        m = msgs[np.searchsorted(t_us, t_ms * 1000, side="right") - 1]
        count[(m.x_m, m.y_m, m.floor)] = count.get((m.x_m, m.y_m, m.floor), 0) + 1
    assert count == {(p["x_m"], p["y_m"], p["floor"]): 8 for p in s["survey_points"]}


def test_office_survey_builtin_grid():
    sc = builtin_scenario("office_survey")
    assert sc["survey"]["enabled"] and sc["world"]["name"] == "default"
    pts = survey_points(__import__("stridefix_sim.world", fromlist=["x"]).default_world(), 2.0, 0.5, [0, 1])
    assert len(pts) == 128  # 64 corridor points per floor
    assert set(np.round((pts[:, 0] - 8) % 2, 9)) == {0} and set(np.round((pts[:, 1] - 5) % 2, 9)) == {0}


@pytest.mark.parametrize(
    "text, key",
    [
        ("[survey]\nlayout = 'spiral'\n", "survey.layout"),
        ("[survey]\nfloor = 5\n", "survey.floor"),
        ("[survey]\nlayout = 'world'\n", "survey.layout"),  # the office has no explicit list
        ("[survey]\nenabled = 1\n", "survey.enabled"),
        ("[walk]\nroute = 'track'\n", "walk.route"),  # the office has no track
        ("[world]\nname = 'aadr2015'\n", "walk.route"),  # the tour needs stairs
    ],
)
def test_bad_survey_and_world_keys(text, key):
    with pytest.raises(ScenarioError, match=f"x.toml: .*'{key}'"):
        parse_scenario(text, source="x.toml")


def test_old_scenarios_bytes_unchanged(default_result, tmp_path):
    for name, (candump_sha, truth_sha) in OLD_BYTES.items():
        r = default_result[0] if name == "default" else simulate(builtin_scenario(name))
        text = "\n".join(r.board.lines) + "\n"
        assert hashlib.sha256(text.encode("ascii")).hexdigest() == candump_sha, name
        write_truth_log(r, tmp_path / f"{name}.lcmlog")
        assert hashlib.sha256((tmp_path / f"{name}.lcmlog").read_bytes()).hexdigest() == truth_sha, name


def test_vectorised_pack_equals_cantools():
    db = load_dbc()
    rng = np.random.default_rng(3)
    for msg in db.messages:
        n = 200
        fields = {}
        for sig in msg.signals:
            lo, hi = sig.minimum, sig.maximum
            if sig.scale == 1 and sig.offset == 0:
                fields[sig.name] = rng.integers(int(lo), int(hi), n, endpoint=True)
            else:
                v = rng.uniform(lo, hi, n)
                v[:3] = [lo, hi, sig.scale * 2.5]  # range ends and a tie (half to even)
                fields[sig.name] = v
        words = pack(msg, fields)
        for i in range(n):
            want = msg.encode({k: (v[i].item()) for k, v in fields.items()}, strict=False)
            got = int(words[i]).to_bytes(8, "little")[: msg.length]
            assert got == want, (msg.name, i)


def test_builtin_names():
    assert {"office_survey", "aadr2015", "aadr2015_slow", "aadr2015_fast", "aadr2015_survey"} <= set(BUILTIN)
