"""Board emulator output: candump syntax, DBC decoding, frame order, seq/time counters, loss, wrap."""

from __future__ import annotations

import json

import numpy as np
import pytest
from stridefix_sim.board import EPOCH_US, emulate_board
from stridefix_sim.scenario import default_scenario
from stridefix_sim.sensors import SensorData

SHORT_S = 25.0  # must match conftest.SHORT_S (checked by test_constants)
WRAP_START_MS = 2**32 - 5_000

ID_TIME, ID_ACCEL, ID_GYRO, ID_MAG, ID_BARO = 0x080, 0x100, 0x101, 0x110, 0x120
ID_BEGIN, ID_AP, ID_END, ID_STATUS = 0x200, 0x201, 0x202, 0x7F0


def summary(out):
    return json.loads((out / "sim_summary.json").read_text())


def decoded(out, dbc, candump):
    return [(t, fid, dbc.decode_message(fid, data)) for t, fid, data in candump(out / "board.candump")]


def count_imu_pairs(frames) -> int:
    """IMU_GYRO frames whose immediately preceding IMU frame is the IMU_ACCEL with the same seq and t_lo."""
    pairs, last_accel = 0, None
    for _, fid, sig in frames:
        if fid == ID_ACCEL:
            last_accel = (sig["seq"], sig["t_lo_ms"])
        elif fid == ID_GYRO:
            if last_accel == (sig["seq"], sig["t_lo_ms"]):
                pairs += 1
            last_accel = None
    return pairs


@pytest.mark.parametrize("run", ["short_run", "lossy_run", "wrap_run"])
def test_every_line_is_candump_and_decodes(run, request, dbc, candump):
    out = request.getfixturevalue(run)
    frames = candump(out / "board.candump")
    assert len(frames) == summary(out)["frames_total"]
    for _, fid, data in frames:
        msg = dbc.get_message_by_frame_id(fid)
        assert len(data) == msg.length
        dbc.decode_message(fid, data)  # raises on a bad frame
    times = [t for t, _, _ in frames]
    assert all(b >= a for a, b in zip(times, times[1:])), "host timestamps must not decrease"


def test_board_time_first_then_every_second(short_run, dbc, candump):
    frames = decoded(short_run, dbc, candump)
    t0, fid0, sig0 = frames[0]
    assert fid0 == ID_TIME
    assert sig0["time_ms"] == 1_000_000
    assert t0 - EPOCH_US - 1_000_000_000 < 1000  # host time = epoch + board time + small latency
    times = [s["time_ms"] for _, f, s in frames if f == ID_TIME]
    assert np.all(np.diff(times) == 1000)
    assert len(times) == int(SHORT_S) + 1


def test_imu_seq_and_t_lo_follow_board_time(short_run, dbc, candump):
    frames = decoded(short_run, dbc, candump)
    start = frames[0][2]["time_ms"]
    accel = [s for _, f, s in frames if f == ID_ACCEL]
    gyro = [s for _, f, s in frames if f == ID_GYRO]
    assert len(accel) == len(gyro) == int(SHORT_S * 100) + 1
    for i, (a, g) in enumerate(zip(accel, gyro)):
        assert a["seq"] == g["seq"] == i % 256
        assert a["t_lo_ms"] == g["t_lo_ms"] == (start + 10 * i) % 256
    for name_id, period in ((ID_MAG, 20), (ID_BARO, 50)):
        samples = [s for _, f, s in frames if f == name_id]
        assert [s["seq"] for s in samples] == [j % 256 for j in range(len(samples))]
        assert [s["t_lo_ms"] for s in samples] == [(start + period * j) % 256 for j in range(len(samples))]
    # the accelerometer pair follows each other directly
    ids = [f for _, f, _ in frames]
    for k, f in enumerate(ids):
        if f == ID_ACCEL:
            assert ids[k + 1] == ID_GYRO


def test_imu_pairs_match_summary(short_run, lossy_run, dbc, candump):
    for out in (short_run, lossy_run):
        assert count_imu_pairs(decoded(out, dbc, candump)) == summary(out)["imu_samples"]
    assert summary(short_run)["imu_samples"] == int(SHORT_S * 100) + 1


def test_loss_rate_drops_frames_and_counts_match(short_run, lossy_run, dbc, candump):
    clean, lossy = summary(short_run), summary(lossy_run)
    assert clean["frames_dropped"] == 0
    assert lossy["frames_dropped"] > 0
    # same seed: the board sends the same frames; loss only removes some of them
    assert lossy["frames_total"] + lossy["frames_dropped"] == clean["frames_total"]
    assert lossy["frames_dropped"] / clean["frames_total"] == pytest.approx(0.1, abs=0.02)
    frames = decoded(lossy_run, dbc, candump)
    assert len(frames) == lossy["frames_total"]
    by_id = {}
    for _, f, _ in frames:
        by_id[f] = by_id.get(f, 0) + 1
    assert by_id[ID_MAG] == lossy["mag_samples"]
    assert by_id[ID_BARO] == lossy["baro_samples"]
    assert by_id[ID_BEGIN] == lossy["wifi_scans"]
    assert by_id[ID_AP] == lossy["wifi_ap_frames"]
    assert lossy["imu_samples"] < clean["imu_samples"]
    assert frames[0][1] == ID_TIME


def test_wifi_scans_are_framed(short_run, dbc, candump):
    frames = decoded(short_run, dbc, candump)
    s = summary(short_run)
    assert s["wifi_scans"] >= int(SHORT_S / 4) - 1
    open_scan, n_ap, scans = None, 0, 0
    for _, f, sig in frames:
        if f == ID_BEGIN:
            assert open_scan is None
            open_scan, n_ap = sig["scan_id"], 0
        elif f == ID_AP:
            assert open_scan is not None
            assert -95 <= sig["rssi"] <= -20
            assert sig["channel"] in (1, 6, 11) or 36 <= sig["channel"] <= 165
            n_ap += 1
        elif f == ID_END:
            assert (sig["scan_id"], sig["n_ap"]) == (open_scan, n_ap)
            assert n_ap > 0
            open_scan = None
            scans += 1
    assert scans == s["wifi_scans"]


def test_board_time_wraps_at_2_pow_32(wrap_run, dbc, candump):
    frames = decoded(wrap_run, dbc, candump)
    bt = [s["time_ms"] for _, f, s in frames if f == ID_TIME]
    assert bt[0] == WRAP_START_MS
    steps = [(b - a) % 2**32 for a, b in zip(bt, bt[1:])]
    assert steps == [1000] * len(steps)
    assert any(b < a for a, b in zip(bt, bt[1:])), "the run must cross the wrap"
    accel = [s for _, f, s in frames if f == ID_ACCEL]
    assert all(a["t_lo_ms"] == (WRAP_START_MS + 10 * i) % 256 for i, a in enumerate(accel))
    # host time keeps increasing across the wrap
    times = [t for t, _, _ in frames]
    assert times[-1] - times[0] == pytest.approx(SHORT_S * 1e6, abs=5000)


def test_values_are_clamped_into_dbc_range(dbc):
    n = 3
    sensors = SensorData(
        accel_mps2=np.array([[1e4, -1e4, 9.8]] * n),
        gyro_dps=np.array([[5000.0, -5000.0, 0.0]] * n),
        mag_idx=np.arange(n),
        mag_ut=np.array([[1e3, -1e3, 0.0]] * n),
        baro_idx=np.arange(n),
        pressure_pa=np.array([2e5] * n),
        temperature_degc=np.array([400.0] * n),
    )
    sc = default_scenario().data
    out = emulate_board(sensors, [], n, sc, np.random.default_rng(0))
    acc = next(
        dbc.decode_message(0x100, bytes.fromhex(ln.split("#")[1])) for ln in out.lines if " 100#" in ln
    )
    assert acc["accel_x"] == pytest.approx(156.9016, abs=0.01)
    assert acc["accel_y"] == pytest.approx(-156.9064, abs=0.01)
    gyr = next(
        dbc.decode_message(0x101, bytes.fromhex(ln.split("#")[1])) for ln in out.lines if " 101#" in ln
    )
    assert gyr["gyro_x"] == pytest.approx(1999.94, abs=0.01)
    baro = next(
        dbc.decode_message(0x120, bytes.fromhex(ln.split("#")[1])) for ln in out.lines if " 120#" in ln
    )
    assert baro["pressure"] == pytest.approx(167772.15)
    assert baro["temperature"] == pytest.approx(327.67)


def test_stdout_streams_the_same_candump(short_run, tmp_path, capsys, sim_cli):
    assert sim_cli(["--duration-s", str(SHORT_S), "--seed", "11", "--stdout", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert captured.out == (short_run / "board.candump").read_text()
    assert not (tmp_path / "board.candump").exists()
    assert (tmp_path / "truth.lcmlog").exists() and (tmp_path / "sim_summary.json").exists()
    assert "steps" in captured.err


def test_constants(short_s, wrap_start_ms):
    assert (SHORT_S, WRAP_START_MS) == (short_s, wrap_start_ms)
