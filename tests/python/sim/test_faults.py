"""Bus and board faults of the board emulator (``[faults]``, stridefix_sim/faults.py): each kind does
what it says on a short walk and counts what it damaged; faults are deterministic by seed, and with
every fault off the output is the clean run's, byte for byte."""

from __future__ import annotations

import functools
import json

import cantools
import numpy as np
import pytest
from stridefix_sim.board import DBC_PATH
from stridefix_sim.pipeline import simulate
from stridefix_sim.scenario import ScenarioError, parse_scenario

SHORT_S = 25.0
SEED = 11
DB = cantools.database.load_file(str(DBC_PATH))
ID_TIME, ID_ACCEL, ID_GYRO, ID_BEGIN = 0x080, 0x100, 0x101, 0x200


def _value(v) -> str:
    return json.dumps(v)


@functools.cache
def run(seed: int = SEED, **faults):
    """GIVEN the short walk of ``seed`` with these ``[faults]`` keys (lists as tuples: cached) WHEN
    simulated THEN its result."""
    toml = f"duration_s = {SHORT_S}\nseed = {seed}\n[faults]\n" + "".join(
        f"{k} = {_value(v)}\n" for k, v in faults.items()
    )
    return simulate(parse_scenario(toml, "<test>"))


def frames(result) -> list[tuple[int, int, bytes]]:
    """(host µs, CAN id, data) of each candump line."""
    out = []
    for line in result.board.lines:
        stamp, _, frame = line.split(" ")
        fid, data = frame.split("#")
        out.append((round(float(stamp[1:-1]) * 1e6), int(fid, 16), bytes.fromhex(data)))
    return out


def payloads(result) -> list[str]:
    return [line.split(" ")[2] for line in result.board.lines]


def record(result) -> dict:
    return result.summary()["faults"]


def test_faults_off_is_the_clean_run_byte_for_byte():
    clean = run()
    off = run(burst_rate=0.0, duplicate_rate=0.0, corrupt_rate=0.0, reset_at_s=(), implausible_at_s=())
    assert off.board.lines == clean.board.lines
    summary = clean.summary()
    assert "faults" not in summary and "faults" not in summary["scenario"]


def test_faults_are_deterministic_by_seed():
    kw = {"duplicate_rate": 0.01, "corrupt_rate": 0.01, "reorder_rate": 0.01, "burst_rate": 0.001}
    assert run(**kw).board.lines == run(**kw).board.lines
    run.cache_clear()
    assert run(**kw).board.lines == run(**kw).board.lines
    assert run(seed=SEED + 1, **kw).board.lines != run(**kw).board.lines


def test_a_fault_does_not_change_the_clean_frames_it_spares():
    """The fault stream is its own: duplicates removed, the frames are the clean run's."""
    clean, dup = payloads(run()), payloads(run(duplicate_rate=0.02))
    undup = [p for k, p in enumerate(dup) if k == 0 or p != dup[k - 1]]
    assert undup == clean


def test_loss_bursts_are_runs_of_lost_frames():
    clean, lossy = run(), run(burst_rate=0.002, burst_frames=15)
    rec = record(lossy)
    assert rec["lost_burst"] > 0 and rec["lost_random"] == 0
    assert len(lossy.board.lines) + rec["lost_burst"] == len(clean.board.lines) == rec["frames_sent_by_board"]
    assert lossy.summary()["frames_dropped"] == rec["frames_lost"] == rec["frames_affected"]
    # every missing stretch is at least part of a burst: few, long gaps
    kept = set(lossy.board.lines)  # (a kept frame keeps its arrival time)
    missing = [line not in kept for line in clean.board.lines]
    starts = sum(1 for a, b in zip([False, *missing], missing) if b and not a)
    assert rec["lost_burst"] / starts >= 10


def test_silence_window_has_no_frame():
    quiet = run(silence_at_s=(10.0,), silence_s=3.0)
    t = np.array([f[0] for f in frames(quiet)])
    t0 = t[0] + 10_000_000
    assert not np.any((t >= t0 + 1000) & (t < t0 + 3_000_000))
    assert np.any((t >= t0 + 3_000_000) & (t < t0 + 3_100_000))
    assert 3 * 270 < record(quiet)["lost_silence"] < 3 * 300  # ~280 frames a second


def test_duplicates_follow_their_original():
    dup = run(duplicate_rate=0.01)
    f = frames(dup)
    rec = record(dup)
    assert len(f) == len(run().board.lines) + rec["duplicated"]
    pairs = sum(1 for a, b in zip(f, f[1:]) if a[1:] == b[1:])
    assert pairs >= rec["duplicated"] > 0
    assert all(b[0] >= a[0] for a, b in zip(f, f[1:]))


def test_reorder_moves_payloads_not_times():
    clean, moved = run(), run(reorder_rate=0.01, reorder_frames=3)
    rec = record(moved)
    assert rec["reordered"] > 0
    assert sorted(payloads(moved)) == sorted(payloads(clean))
    assert [f[0] for f in frames(moved)] == [f[0] for f in frames(clean)]
    changed = sum(a != b for a, b in zip(payloads(moved), payloads(clean)))
    assert rec["reordered"] < changed <= 4 * rec["reordered"]  # each move shifts reorder_frames + 1


@pytest.mark.parametrize("bits", [1, 3])
def test_corruption_flips_exactly_the_bits(bits):
    clean, bad = frames(run()), run(corrupt_rate=0.01, corrupt_bits=bits)
    rec = record(bad)
    diff = [(a, b) for a, b in zip(clean, frames(bad)) if a != b]
    assert len(diff) == rec["corrupted"] > 0
    for a, b in diff:
        assert a[:2] == b[:2]
        flipped = int.from_bytes(a[2], "little") ^ int.from_bytes(b[2], "little")
        assert bin(flipped).count("1") == bits


def test_board_reset_restarts_time_counters_and_boot_id():
    reset = run(reset_at_s=(12.0,), reset_down_ms=300, reset_time_start_ms=5)
    rec = record(reset)
    assert rec["resets"] == 1 and rec["boot_ids"] == [7, 8]
    f = frames(reset)
    t_reset = f[0][0] + 12_000_000
    before = [x for x in f if x[0] < t_reset]
    after = [x for x in f if x[0] >= t_reset]
    assert after[0][0] >= t_reset + 300_000, "nothing is sent while the board reboots"
    assert after[0][1] == ID_TIME
    first = DB.decode_message(ID_TIME, after[0][2])
    assert (first["time_ms"], first["boot_id"]) == (5, 8)
    assert DB.decode_message(ID_TIME, before[-1][2] if before[-1][1] == ID_TIME else f[0][2])["boot_id"] == 7
    accel = [DB.decode_message(ID_ACCEL, x[2]) for x in after if x[1] == ID_ACCEL]
    assert [a["seq"] for a in accel[:300]] == [k % 256 for k in range(300)]
    assert accel[0]["t_lo_ms"] == 5
    scans = [DB.decode_message(ID_BEGIN, x[2])["scan_id"] for x in after if x[1] == ID_BEGIN]
    assert scans[:3] == [0, 1, 2]
    assert rec["unsent_reset"] > 0


def test_implausible_bitflip_is_one_frame_one_bit():
    clean, bad = frames(run()), frames(run(implausible_at_s=(10.0,)))
    diff = [(a, b) for a, b in zip(clean, bad) if a != b]
    assert len(diff) == 1
    ((a, b),) = diff
    assert a[1] == ID_ACCEL
    za, zb = (DB.decode_message(ID_ACCEL, x[2])["accel_z"] for x in (a, b))
    assert 5 < za < 15 and zb < -140  # the sign bit: 9.x -> -14x m/s2, inside the int16 range


def test_implausible_full_scale():
    bad = run(implausible_rate=0.01, implausible_mode="full_scale", implausible_signal="gyro_x")
    n = record(bad)["implausible"]
    gyro = [DB.decode_message(ID_GYRO, x[2])["gyro_x"] for x in frames(bad) if x[1] == ID_GYRO]
    full = DB.get_message_by_frame_id(ID_GYRO).get_signal_by_name("gyro_x").maximum
    assert n > 0 and sum(abs(g - full) < 0.1 for g in gyro) == n


def test_board_time_stuck_repeats_the_value_of_its_start():
    """From 5 s for 10 s BOARD_TIME carries the board time of 5 s; the samples go on as sent."""
    clean, stuck = frames(run()), run(board_time_stuck_at_s=(5.0,), board_time_stuck_s=10.0)
    f = frames(stuck)
    assert [x[:2] for x in f] == [x[:2] for x in clean]
    diff = [(a, b) for a, b in zip(clean, f) if a != b]
    assert {a[1] for a, _ in diff} == {ID_TIME}
    times = [DB.decode_message(ID_TIME, x[2]) for x in f if x[1] == ID_TIME]
    t0 = times[0]["time_ms"]
    want = [0, 1000, 2000, 3000, 4000] + [5000] * 10 + [15000, 16000]
    assert [m["time_ms"] - t0 for m in times[:17]] == want
    assert {m["boot_id"] for m in times} == {7}
    rec = record(stuck)
    assert rec["board_time_stuck"] == len(diff) == 9  # the frame at 5 s carries its true time
    assert rec["frames_affected"] == 9


def test_imu_failed_reads_full_scale_on_every_axis():
    """From 10 s for 5 s every IMU_ACCEL and IMU_GYRO signal is at the DBC's largest raw value (a
    failed sensor, as the board encodes it: the signals are integers, NaN has no encoding); seq and
    t_lo go on."""
    clean, bad = frames(run()), run(imu_failed_at_s=(10.0,), imu_failed_s=5.0)
    f = frames(bad)
    assert [x[:2] for x in f] == [x[:2] for x in clean]
    diff = [(a, b) for a, b in zip(clean, f) if a != b]
    assert {a[1] for a, _ in diff} == {ID_ACCEL, ID_GYRO}
    t_start = clean[0][0] + 10_000_000
    assert all(t_start <= a[0] < t_start + 5_000_000 + 10_000 for a, _ in diff)
    for a, b in diff:
        ma, mb = (DB.decode_message(x[1], x[2], scaling=False) for x in (a, b))
        assert (ma["seq"], ma["t_lo_ms"]) == (mb["seq"], mb["t_lo_ms"])
        for sig in DB.get_message_by_frame_id(a[1]).signals:
            if sig.name not in ("seq", "t_lo_ms"):
                assert sig.is_signed and mb[sig.name] == 2 ** (sig.length - 1) - 1  # int16: 32767
    assert record(bad)["imu_failed"] == len(diff) == 2 * 500


@pytest.mark.parametrize(
    "text, key",
    [
        ("duplicate_rate = 1.0", "faults.duplicate_rate"),
        ("burst_frames = 0", "faults.burst_frames"),
        ("corrupt_bits = 65", "faults.corrupt_bits"),
        ("reset_at_s = [-1]", "faults.reset_at_s"),
        ("reset_at_s = [10, 10.1]", "faults.reset_at_s"),
        ("reset_at_s = 10", "faults.reset_at_s"),
        ('silence_at_s = ["a"]', "faults.silence_at_s"),
        ("silence_s = 0", "faults.silence_s"),
        ('implausible_signal = "pressure"', "faults.implausible_signal"),
        ('implausible_mode = "nan"', "faults.implausible_mode"),
        ("reset_time_start_ms = 4294967296", "faults.reset_time_start_ms"),
        ("reorder_frames = 101", "faults.reorder_frames"),
        ("board_time_stuck_at_s = [-1]", "faults.board_time_stuck_at_s"),
        ("board_time_stuck_s = 0", "faults.board_time_stuck_s"),
        ("imu_failed_at_s = [-0.5]", "faults.imu_failed_at_s"),
        ("imu_failed_s = -1", "faults.imu_failed_s"),
        ("imu_failed_s = 1e9", "faults.imu_failed_s"),
        ("bogus = 1", "faults.bogus"),
    ],
)
def test_bad_fault_keys_are_refused_by_name(text, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        parse_scenario(f"[faults]\n{text}\n", "<test>")
