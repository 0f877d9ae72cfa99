"""Truth outputs and determinism: the TRUTH log, the summary, init_truth.ini, same seed → same bytes."""

from __future__ import annotations

import configparser
import json

import lcm
import numpy as np
import pytest
from stridefix import truth_t

SHORT_S = 25.0  # conftest.SHORT_S
WRAP_START_MS = 2**32 - 5_000  # conftest.WRAP_START_MS


def truth(out):
    msgs = []
    for ev in lcm.EventLog(str(out / "truth.lcmlog"), "r"):
        assert ev.channel == "TRUTH"
        m = truth_t.decode(ev.data)
        assert ev.timestamp == m.t_us
        msgs.append(m)
    return msgs


def summary(out):
    return json.loads((out / "sim_summary.json").read_text())


def test_same_seed_same_bytes_other_seed_differs(sim_run, short_run):
    again = sim_run("--seed", "11", "--duration-s", str(SHORT_S))  # same run, other argument order
    assert again != short_run
    for name in ("board.candump", "truth.lcmlog"):
        assert (again / name).read_bytes() == (short_run / name).read_bytes()
    other = sim_run("--duration-s", str(SHORT_S), "--seed", "12")
    for name in ("board.candump", "truth.lcmlog"):
        assert (other / name).read_bytes() != (short_run / name).read_bytes()


def test_truth_log_is_10_hz_on_the_board_clock(short_run):
    msgs = truth(short_run)
    assert len(msgs) == int(SHORT_S * 10) + 1 == summary(short_run)["truth_messages"]
    t = np.array([m.t_us for m in msgs])
    assert t[0] == 1_000_000 * 1000
    assert np.all(np.diff(t) == 100_000)
    assert all(m.source == truth_t.SOURCE_SIMULATION and m.floor == 0 for m in msgs)
    assert all(-np.pi <= m.heading_rad <= np.pi for m in msgs)
    xy = np.array([[m.x_m, m.y_m] for m in msgs])
    assert np.all((xy >= 0) & (xy <= [60, 30]))
    # positions move at walking speed at most
    assert np.max(np.hypot(*np.diff(xy, axis=0).T)) < 0.25


def test_truth_time_is_unwrapped_across_board_time_wrap(wrap_run):
    t = np.array([m.t_us for m in truth(wrap_run)])
    assert t[0] == WRAP_START_MS * 1000
    assert t[-1] > 2**32 * 1000
    assert np.all(np.diff(t) == 100_000)


def test_summary_steps_equal_truth_log_last_step_count(short_run):
    msgs = truth(short_run)
    s = summary(short_run)
    assert s["steps"] == msgs[-1].step_count > 0
    counts = [m.step_count for m in msgs]
    assert all(b >= a for a, b in zip(counts, counts[1:]))
    assert s["distance_m"] == pytest.approx(
        sum(np.hypot(b.x_m - a.x_m, b.y_m - a.y_m) for a, b in zip(msgs, msgs[1:])), rel=0.02
    )
    for key in (
        "seed",
        "duration_s",
        "distance_m",
        "steps",
        "imu_samples",
        "mag_samples",
        "baro_samples",
        "wifi_scans",
        "wifi_ap_frames",
        "frames_total",
        "frames_dropped",
        "board_time_start_ms",
        "init",
        "floors_visited",
        "activity_s",
        "pace",
        "weinberg_k",
        "map_rotation_deg",
    ):
        assert key in s


def test_cadence_is_between_1_6_and_2_0_hz(short_run):
    msgs = truth(short_run)
    t_s = np.array([m.t_us for m in msgs]) / 1e6
    c = np.array([m.step_count for m in msgs])
    walking = np.nonzero(np.diff(c))[0]
    t_first, t_last = t_s[walking[0] + 1], t_s[walking[-1] + 1]
    rate_hz = (c[walking[-1] + 1] - c[walking[0] + 1]) / (t_last - t_first)
    assert 1.6 <= rate_hz <= 2.0


def test_init_truth_ini_is_the_first_truth_pose(short_run):
    ini = configparser.ConfigParser()
    ini.read(short_run / "init_truth.ini")
    first = truth(short_run)[0]
    assert float(ini["init"]["x_m"]) == pytest.approx(first.x_m, abs=1e-3)
    assert float(ini["init"]["y_m"]) == pytest.approx(first.y_m, abs=1e-3)
    assert float(ini["init"]["heading_rad"]) == pytest.approx(first.heading_rad, abs=1e-6)
    assert int(ini["init"]["floor"]) == 0
    assert summary(short_run)["init"] == {
        "x_m": first.x_m,
        "y_m": first.y_m,
        "heading_rad": pytest.approx(first.heading_rad, abs=1e-6),
        "floor": 0,
    }


def test_default_scenario_is_the_two_floor_tour_and_fast(default_result):
    r, elapsed = default_result
    s = r.summary()
    assert elapsed < 15.0
    assert 240 <= s["duration_s"] <= 360  # 4-6 minutes
    assert s["route"] == "tour" and s["pace"] == "normal"
    assert s["floors_visited"] == [0, 1]
    assert s["map_rotation_deg"] == 20.0
    assert 0.45 <= s["weinberg_k"] <= 0.55
    act = s["activity_s"]
    assert set(act) == {"walking", "still", "stairs", "elevator"}
    assert sum(act.values()) == pytest.approx(s["duration_s"], abs=0.02)
    assert act["stairs"] > 8 and 4 < act["elevator"] < 10 and act["still"] > 20 and act["walking"] > 200
    assert s["distance_m"] == pytest.approx(r.walk.route.length_m, rel=1e-3)
    # standing still at the start, at the three pauses, in the elevator and at the end
    still = r.walk.speed_mps == 0
    runs = np.diff(np.flatnonzero(np.diff(np.concatenate([[0], still.astype(int), [0]]))))[::2]
    assert sum(n >= 300 for n in runs) >= 6
