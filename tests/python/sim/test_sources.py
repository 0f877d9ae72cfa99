"""The sources beyond Wi-Fi: BLE path loss, the GNSS error process, landmark events at the
doors, their CAN frames, and the campus world's route (walls, outdoor stretch)."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from stridefix_common.geodesy import project
from stridefix_sim.ble import simulate_ble
from stridefix_sim.board import load_dbc
from stridefix_sim.gnss import MODE_DOOR, MODE_OUTDOOR, gauss_markov, simulate_gnss
from stridefix_sim.pipeline import simulate
from stridefix_sim.radio import walls_crossed
from stridefix_sim.scenario import builtin_scenario
from stridefix_sim.world_sources import Beacon, inside
from stridefix_sim.worlds import load_world


@pytest.fixture(scope="module")
def campus_run():
    """The campus walk (seed 1), simulated in-process once."""
    return simulate(builtin_scenario("campus"))


def standing_walk(points_xy, seconds_each: float, rate_hz: float = 100.0):
    """A walker standing ``seconds_each`` at each point in turn (what simulate_ble/gnss read of a Walk)."""
    n = int(seconds_each * rate_hz)
    xy = np.repeat(np.asarray(points_xy, float), n, axis=0)
    t = np.arange(len(xy)) / rate_hz
    return SimpleNamespace(
        t_s=t, x_m=xy[:, 0], y_m=xy[:, 1], level_m=np.zeros(len(xy)), floor=np.zeros(len(xy), np.int64)
    )


def test_ble_mean_rssi_follows_log_distance_at_known_distances():
    # GIVEN one beacon at the board's height (d = horizontal distance), no walls, n = 2.2, sigma 4 dB
    sc = builtin_scenario("campus").data
    height = sc["baro"]["sensor_height_m"]
    beacon = Beacon(mac=0x020000000001, x_m=0.0, y_m=0.0, z_m=height, rssi_1m_dbm=-59.0, adv_interval_ms=200)
    world = dataclasses.replace(load_world("campus", 20.0), walls_m=np.zeros((0, 4)), beacons=(beacon,))
    distances = [1.0, 2.0, 5.0, 10.0]
    walk = standing_walk([(d, 0.0) for d in distances], 1000.0)
    # WHEN it advertises for 1000 s at each distance
    ads = simulate_ble(sc, world, walk, np.random.default_rng(5))
    # THEN the mean RSSI at each distance is rssi_1m - 10 n log10(d) within 0.2 dB
    n = sc["ble"]["path_loss_exponent"]
    for k, d in enumerate(distances):
        sel = (ads.t_ms >= k * 1_000_000 + 1000) & (ads.t_ms < (k + 1) * 1_000_000 - 1000)
        expected = -59.0 - 10.0 * n * math.log10(d)
        assert abs(np.mean(ads.rssi_dbm[sel]) - expected) < 0.2, (d, np.mean(ads.rssi_dbm[sel]), expected)
        assert abs(np.std(ads.rssi_dbm[sel]) - sc["ble"]["shadowing_db"]) < 0.2
    # and the rate is one advertisement per (interval + mean advDelay), times (1 - loss)
    rate_hz = len(ads) / (walk.t_s[-1])
    expected_hz = 1000.0 / (200.0 + sc["ble"]["adv_jitter_ms"] / 2) * (1.0 - sc["ble"]["loss_rate"])
    assert rate_hz == pytest.approx(expected_hz, rel=0.02)


def test_ble_wall_between_costs_the_wall_loss():
    sc = builtin_scenario("campus").data
    height = sc["baro"]["sensor_height_m"]
    beacon = Beacon(mac=1, x_m=0.0, y_m=0.0, z_m=height, rssi_1m_dbm=-59.0)
    wall = np.array([[2.5, -5.0, 2.5, 5.0]])
    walk = standing_walk([(2.0, 0.0), (3.0, 0.0)], 800.0)
    free = dataclasses.replace(load_world("campus", 20.0), walls_m=np.zeros((0, 4)), beacons=(beacon,))
    walled = dataclasses.replace(free, walls_m=wall)
    a = simulate_ble(sc, free, walk, np.random.default_rng(1))
    b = simulate_ble(sc, walled, walk, np.random.default_rng(1))
    far = lambda ads: ads.rssi_dbm[ads.t_ms > 801_000]  # noqa: E731  (beyond the wall)
    assert np.mean(far(a)) - np.mean(far(b)) == pytest.approx(sc["radio"]["wall_loss_db"], abs=0.3)


def test_gauss_markov_sigma_and_correlation_time():
    # GIVEN a long 1 Hz run of the GNSS error process (sigma 4 m, tau 45 s)
    e = gauss_markov(400_000, 1.0, 4.0, 45.0, np.random.default_rng(2))
    # THEN its std is sigma within 3 % and the correlation time from the lag-1 and lag-45 autocorrelation
    # is tau within 10 %
    assert np.std(e) == pytest.approx(4.0, rel=0.03)
    for lag in (1, 45):
        rho = np.corrcoef(e[:-lag], e[lag:])[0, 1]
        assert -lag / math.log(rho) == pytest.approx(45.0, rel=0.10)


def test_gnss_outdoors_honest_indoors_none_near_doors_degraded():
    sc = builtin_scenario("campus").data
    world = load_world("campus", 20.0)
    g = sc["gnss"]
    # GIVEN a walker standing 3 h outdoors, 1 h deep inside, 1 h inside 2 m from the west door
    walk = standing_walk([(-20.0, -10.0)] * 3 + [(20.0, 15.0), (2.0, 10.0)], 3600.0)
    fx = simulate_gnss(sc, world, walk, np.random.default_rng(3))
    out, door = fx.mode == MODE_OUTDOOR, fx.mode == MODE_DOOR
    # THEN outdoors a fix every second; none deep inside; near the door about door_fix_prob of them
    assert out.sum() == pytest.approx(3 * 3600, abs=2)
    assert not np.any((fx.t_ms >= 3 * 3_600_000) & (fx.t_ms < 4 * 3_600_000))
    assert door.sum() / 3600 == pytest.approx(g["door_fix_prob"], abs=0.05)
    # outdoors the per-axis error std is sigma (within 10 %: 3 h = 240 correlation times) and the
    # reported accuracy is that sigma (median within 3 %)
    ex, ey = fx.x_m - fx.truth_x_m, fx.y_m - fx.truth_y_m
    assert np.std(np.concatenate([ex[out], ey[out]])) == pytest.approx(g["sigma_m"], rel=0.10)
    assert np.median(fx.accuracy_m[out]) == pytest.approx(g["sigma_m"], rel=0.03)
    # near the door the error and the accuracy are door_sigma_factor times larger
    assert np.median(fx.accuracy_m[door]) == pytest.approx(g["sigma_m"] * g["door_sigma_factor"], rel=0.05)
    # latitude/longitude map back through the analyzer's projection to the fix position within 1 mm
    e_m, n_m = project(fx.lat_deg, fx.lon_deg, world.geo.origin_lat_deg, world.geo.origin_lon_deg)
    x_m, y_m = world.geo.en_to_map(e_m, n_m)
    assert np.max(np.hypot(x_m - fx.x_m, y_m - fx.y_m)) < 1e-3


def test_campus_route_crosses_no_wall_and_has_60_m_outdoors(campus_run):
    w, world = campus_run.walk, campus_run.world
    assert walls_crossed(w.x_m[:-1], w.y_m[:-1], w.x_m[1:], w.y_m[1:], world.walls_m).sum() == 0
    out = ~inside(world.footprint_m, w.x_m, w.y_m)
    ds = np.diff(w.s_m)
    assert float(np.sum(ds[out[1:] & out[:-1]])) >= 60.0
    assert 6 <= len(world.beacons) and len(world.doors) == 2


def test_landmark_events_at_the_doors_only(campus_run):
    w, world = campus_run.walk, campus_run.world
    events = campus_run.sources.landmarks
    # one event per door, in walking order (west door out, south door in), at the door's tag
    assert [e.landmark_id for e in events] == [1, 2]
    for e in events:
        door = next(d for d in world.doors if d.landmark_id == e.landmark_id)
        assert (e.x_m, e.y_m, e.floor) == (door.x_m, door.y_m, door.floor)
        k = int(round(e.t_ms / 10))
        assert math.hypot(w.x_m[k] - door.x_m, w.y_m[k] - door.y_m) <= 0.5
    # and the walk comes within 0.5 m of a tag nowhere else
    d = np.min([np.hypot(w.x_m - dr.x_m, w.y_m - dr.y_m) for dr in world.doors], axis=0)
    near_t = w.t_s[d <= 0.5]
    assert all(min(abs(t - e.t_ms / 1000) for e in events) < 2.0 for t in near_t)
    # the default office has no tags: no event
    assert not simulate(builtin_scenario("pace_fast").with_overrides(duration_s=20.0)).sources.landmarks


def _decoded(run, name):
    db = load_dbc()
    msg = db.get_message_by_name(name)
    rows = []
    for line in run.board.lines:
        frame = line.split()[2]
        fid, data = frame.split("#")
        if int(fid, 16) == msg.frame_id:
            rows.append(msg.decode(bytes.fromhex(data)))
    return rows


def test_source_frames_decode_with_cantools_to_the_values_sent(campus_run):
    src, start = campus_run.sources, campus_run.board_time_start_ms
    ble = _decoded(campus_run, "BLE_ADV")
    assert len(ble) == len(src.ble) > 1000
    assert [r["beacon_id"] for r in ble] == src.ble.mac.tolist()
    assert [r["rssi"] for r in ble] == src.ble.rssi_dbm.tolist()
    assert [r["t_lo_ms"] for r in ble] == ((start + src.ble.t_ms) % 256).tolist()
    lm = _decoded(campus_run, "LANDMARK")
    assert [(r["x"], r["y"], r["floor"]) for r in lm] == [(e.x_m, e.y_m, e.floor) for e in src.landmarks]
    assert [r["t_lo_ms"] for r in lm] == [(start + e.t_ms) % 256 for e in src.landmarks]
    info, pos = _decoded(campus_run, "GNSS_INFO"), _decoded(campus_run, "GNSS_POSITION")
    fx = src.gnss
    assert len(info) == len(pos) == len(fx) >= 50
    assert [r["time_ms"] for r in info] == ((start + fx.t_ms) % 2**32).tolist()
    np.testing.assert_allclose([r["accuracy"] for r in info], fx.accuracy_m, atol=0.05 + 1e-9)
    np.testing.assert_allclose([r["altitude"] for r in info], fx.alt_m, atol=0.05 + 1e-9)
    np.testing.assert_allclose([r["latitude"] for r in pos], fx.lat_deg, atol=0.5e-7 + 1e-12)
    np.testing.assert_allclose([r["longitude"] for r in pos], fx.lon_deg, atol=0.5e-7 + 1e-12)
    # GNSS_INFO goes just before the GNSS_POSITION of the same fix
    ids = [line.split()[2].split("#")[0] for line in campus_run.board.lines]
    i_info = [i for i, f in enumerate(ids) if f == "301"]
    assert all(ids[i + 1] == "300" for i in i_info)
