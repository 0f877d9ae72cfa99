"""Two floors: the true floor changes exactly on the stairs and in the elevator, the barometer sees
the storey height, the elevator's ride is in the accelerometer, Wi-Fi is attenuated across floors,
the TRUTH log carries floor and heading."""

from __future__ import annotations

import math

import lcm
import numpy as np
import pytest
from stridefix import truth_t
from stridefix_sim.pipeline import TRUTH_CHANNEL, write_truth_log
from stridefix_sim.sensors import pressure_pa
from stridefix_sim.walker import ACT_ELEVATOR, ACT_STAIRS, ACT_STILL, ACT_WALK, MODE_STAIRS, MODE_WALK


def spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """[start, end) index runs where ``mask`` is true."""
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def test_floor_changes_exactly_on_the_stairs_and_in_the_elevator(default_result):
    r, _ = default_result
    w = r.walk
    changes = np.flatnonzero(np.diff(w.floor)) + 1
    assert len(changes) == 2
    up, down = changes
    assert (w.floor[up - 1], w.floor[up]) == (0, 1) and w.activity[up] == ACT_STAIRS
    assert (w.floor[down - 1], w.floor[down]) == (1, 0) and w.activity[down] == ACT_ELEVATOR
    # the level only changes on stairs (or the landing between flights) and in the elevator
    moving_level = np.abs(np.gradient(w.level_m)) > 1e-6
    stairs = spans(w.activity == ACT_STAIRS)
    zone = np.zeros(len(w.t_s), bool)
    zone[stairs[0][0] - 100 : stairs[-1][1] + 100] = True  # flights, landing and the blends
    assert np.all(zone[moving_level] | (w.activity[moving_level] == ACT_ELEVATOR))
    assert w.level_m[0] == 0.0 and w.level_m[-1] == 0.0
    assert w.level_m.max() == pytest.approx(r.world.storey_m, abs=1e-9)


def test_stairs_are_slower_and_shorter_with_the_right_vertical_speed(default_result):
    r, _ = default_result
    w = r.walk
    on_stairs = w.activity == ACT_STAIRS
    assert 0.2 <= w.vz_mps[on_stairs].mean() <= 0.3
    T = np.diff(w.step_t_s)
    stairs_k = np.flatnonzero(w.step_mode[:-1] == MODE_STAIRS)[1:-1]
    walk_k = np.flatnonzero(w.step_mode[:-1] == MODE_WALK)
    assert len(stairs_k) >= 15
    assert np.median(T[stairs_k]) > 1.1 * np.median(T[walk_k])
    assert np.median(w.step_len_m[stairs_k]) == pytest.approx(r.world.stairs.tread_m, rel=0.1)


def test_elevator_ride_shows_in_the_accelerometer(default_result):
    r, _ = default_result
    w = r.walk
    ((a, b),) = spans(w.activity == ACT_ELEVATOR)
    assert (b - a) / 100 == pytest.approx(6.0, abs=1.5)  # 3.5 m at ≤ 1 m/s with 0.8 m/s² ramps
    assert w.vz_mps[a:b].min() == pytest.approx(-1.0, abs=0.01)
    g = r.sensors.accel_mps2[:200].mean(axis=0)
    up = g / np.linalg.norm(g)
    vert = r.sensors.accel_mps2 @ up - np.linalg.norm(g)
    ride = vert[a:b]
    # going down: lighter while accelerating, heavier while braking
    assert ride.min() < -0.6 and ride.max() > 0.6
    assert np.argmin(ride) < np.argmax(ride)
    before = vert[a - 100 : a]
    assert np.abs(before).max() < 0.15  # standing still in the cab before it moves
    assert np.all(w.speed_mps[a:b] == 0)


def test_barometer_sees_the_storey_height(default_result):
    r, _ = default_result
    w = r.walk
    s = r.sensors
    t_b = w.t_s[s.baro_idx]
    act_b = w.activity[s.baro_idx]
    storey = r.world.storey_m
    expected = pressure_pa(np.array([1.1]), 101325.0)[0] - pressure_pa(np.array([1.1 + storey]), 101325.0)[0]
    assert expected == pytest.approx(storey * 12.0, rel=0.01)
    stairs = spans(w.activity == ACT_STAIRS)
    t_up0, t_up1 = w.t_s[stairs[0][0]], w.t_s[stairs[-1][1] - 1]
    below = (t_b > t_up0 - 12) & (t_b < t_up0 - 2)
    above = (t_b > t_up1 + 2) & (t_b < t_up1 + 12)
    assert s.pressure_pa[below].mean() - s.pressure_pa[above].mean() == pytest.approx(expected, abs=5.0)
    ((a, b),) = spans(w.activity == ACT_ELEVATOR)
    ta, tb = w.t_s[a], w.t_s[b - 1]
    in_cab_up = (t_b > ta - 2.5) & (t_b < ta) & (act_b == ACT_STILL)
    in_cab_down = (t_b > tb) & (t_b < tb + 1.8) & (act_b == ACT_STILL)
    assert s.pressure_pa[in_cab_down].mean() - s.pressure_pa[in_cab_up].mean() == pytest.approx(
        expected, abs=5.0
    )


def test_barometer_drift_is_a_slow_random_walk(default_result):
    r, _ = default_result
    drift = r.sensors.baro_drift_pa
    assert drift[0] == 0.0
    # 20 Pa per √hour: after ~5.5 minutes a few Pa, never a jump
    assert np.abs(drift).max() < 25.0
    assert np.abs(np.diff(drift)).max() < 0.5


def test_wifi_is_attenuated_across_floors(default_result):
    r, _ = default_result
    w = r.walk
    by_bssid = {ap.bssid: ap for ap in r.world.aps}
    diffs = []
    for scan in r.scans:
        i = min(int(round(scan.t_ms / 10)), len(w.t_s) - 1)
        f = int(w.floor[i])
        same = [rssi for b, rssi, _ in scan.aps if by_bssid[b].floor == f]
        other = [rssi for b, rssi, _ in scan.aps if by_bssid[b].floor != f]
        assert len(same) >= 3
        if other:
            diffs.append(np.mean(sorted(same)[-3:]) - np.mean(sorted(other)[-3:]))
    # same plan position on both floors: the other floor's strongest APs are ~15 dB (+ distance) weaker
    assert np.median(diffs) > 12.0
    floors_heard = {by_bssid[b].floor for s in r.scans for b, _, _ in s.aps}
    assert floors_heard == {0, 1}


def test_truth_log_carries_floor_and_walking_heading(default_result, tmp_path):
    r, _ = default_result
    write_truth_log(r, tmp_path / "truth.lcmlog")
    msgs = [
        truth_t.decode(e.data)
        for e in lcm.EventLog(str(tmp_path / "truth.lcmlog"), "r")
        if e.channel == TRUTH_CHANNEL
    ]
    idx = r.truth_indices()
    assert len(msgs) == len(idx)
    assert [m.floor for m in msgs] == r.walk.floor[idx].tolist()
    assert {m.floor for m in msgs} == {0, 1}
    # heading = direction of travel in the map frame (while walking straight)
    x = np.array([m.x_m for m in msgs])
    y = np.array([m.y_m for m in msgs])
    hd = np.array([m.heading_rad for m in msgs])
    moved = np.hypot(np.diff(x), np.diff(y)) > 0.05
    travel = np.arctan2(np.diff(y), np.diff(x))
    err = np.angle(np.exp(1j * (travel - hd[:-1])))[moved]
    assert np.percentile(np.abs(err), 95) < math.radians(10)
    assert np.all(np.abs(hd) <= math.pi + 1e-6)
    assert msgs[-1].step_count == r.steps
    act = r.walk.activity[idx]
    assert (act == ACT_WALK).any()
