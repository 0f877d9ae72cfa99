"""A failed IMU does not fill the disk: the log of a walk whose IMU fails mid-walk holds no more
poses than the clean walk's.

Regression: when the sample gate refused IMU samples (stuck at full scale, NaN), stridefixd wrote
every POSE channel for every refused sample, all with the same stale t_us (the decision compared the
refused sample's time with the estimator's last pose time, which no longer moved): IMU stuck at full
scale from 150 s of the demo walk gave 179,919 POSE messages instead of 32,823 and a log 2.8 times
as large. GIVEN the default walk, WHEN its IMU fails at 150 s (accel_z stuck at full scale in the
CAN frames; or NaN accelerations in the raw-sensor LCM log it replays), THEN each POSE channel holds
at most the clean walk's messages, and no two consecutive messages of a channel carry the same t_us.
"""

from __future__ import annotations

import math
import subprocess
from collections import Counter
from pathlib import Path

import cantools
import lcm
import pytest
from stridefix.imu_t import imu_t
from stridefix.pose_t import pose_t
from stridefix_common.dbc import DBC_PATH

FAIL_AT_S = 150.0
RAW_CHANNELS = {"IMU", "MAG", "BARO", "WIFI", "GNSS", "BLE", "LANDMARK"}


def run(stridefixd: Path, source: list[str], log: Path) -> str:
    proc = subprocess.run(
        [str(stridefixd), *source, "-l", str(log), "-q"], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    return proc.stderr


def pose_counts_and_repeats(log: Path) -> tuple[Counter, Counter]:
    """Per POSE channel: its messages, and how many of them repeat the t_us of the one before."""
    counts: Counter = Counter()
    repeats: Counter = Counter()
    last: dict[str, int] = {}
    for e in lcm.EventLog(str(log), "r"):
        if e.channel.startswith("POSE"):
            t_us = pose_t.decode(e.data).t_us
            counts[e.channel] += 1
            repeats[e.channel] += last.get(e.channel) == t_us
            last[e.channel] = t_us
    return counts, repeats


def imu_stuck_at_full_scale(candump: Path, out: Path, until_s: float = math.inf) -> None:
    """The walk's candump with accel_z at full scale in every IMU_ACCEL frame from FAIL_AT_S on
    (until until_s)."""
    db = cantools.database.load_file(str(DBC_PATH))
    accel = db.get_message_by_name("IMU_ACCEL")
    full_scale = accel.get_signal_by_name("accel_z").maximum
    lines = candump.read_text().splitlines(keepends=True)
    t0 = float(lines[0][1 : lines[0].index(")")])
    changed = []
    for line in lines:
        stamp, _iface, frame = line.split()
        can_id, data = frame.split("#")
        if int(can_id, 16) == accel.frame_id and FAIL_AT_S <= float(stamp[1:-1]) - t0 < until_s:
            signals = accel.decode(bytes.fromhex(data), decode_choices=False)
            signals["accel_z"] = full_scale
            line = f"{stamp} {_iface} {can_id}#{accel.encode(signals).hex().upper()}\n"
        changed.append(line)
    out.write_text("".join(changed))


def raw_sensor_log(log: Path, out: Path, nan_from_us: int | None) -> None:
    """The raw-sensor channels of a stridefixd log, as a replay input; with nan_from_us, every IMU
    sample from then on has NaN accelerations."""
    w = lcm.EventLog(str(out), "w", overwrite=True)
    for e in lcm.EventLog(str(log), "r"):
        if e.channel not in RAW_CHANNELS:
            continue
        data = e.data
        if e.channel == "IMU" and nan_from_us is not None:
            m = imu_t.decode(data)
            if m.t_us >= nan_from_us:
                m.accel_mps2 = [math.nan] * 3
                data = m.encode()
        w.write_event(e.timestamp, e.channel, data)
    w.close()


@pytest.fixture(scope="module")
def clean(stridefixd, default_walk, tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("failed_imu")
    log = out / "clean.lcmlog"
    run(stridefixd, ["-i", str(default_walk["dir"] / "board.candump")], log)
    first_imu_us = next(imu_t.decode(e.data).t_us for e in lcm.EventLog(str(log), "r") if e.channel == "IMU")
    return {"dir": out, "log": log, "fail_us": first_imu_us + round(FAIL_AT_S * 1e6)}


def assert_no_more_poses_than_clean(clean_log: Path, failed_log: Path, stderr: str) -> None:
    want, _ = pose_counts_and_repeats(clean_log)
    got, repeats = pose_counts_and_repeats(failed_log)
    assert "samples refused: 0 out of range" not in stderr, stderr  # the gate did refuse the IMU
    assert set(got) == set(want) == {"POSE", "POSE_PDR_ONLY"}
    for channel, n in got.items():
        assert n <= want[channel], (channel, n, want[channel])
    assert sum(repeats.values()) == 0, repeats


def test_imu_stuck_at_full_scale_writes_no_more_poses(stridefixd, default_walk, clean, tmp_path):
    candump = tmp_path / "stuck.candump"
    imu_stuck_at_full_scale(default_walk["dir"] / "board.candump", candump)
    log = tmp_path / "stuck.lcmlog"
    stderr = run(stridefixd, ["-i", str(candump)], log)
    assert_no_more_poses_than_clean(clean["log"], log, stderr)


def test_imu_nan_in_a_replay_writes_no_more_poses(stridefixd, clean, tmp_path):
    raw, nan = tmp_path / "raw.lcmlog", tmp_path / "nan.lcmlog"
    raw_sensor_log(clean["log"], raw, None)
    raw_sensor_log(clean["log"], nan, clean["fail_us"])
    replay_clean, replay_nan = tmp_path / "replay_clean.lcmlog", tmp_path / "replay_nan.lcmlog"
    run(stridefixd, ["--replay", str(raw)], replay_clean)
    stderr = run(stridefixd, ["--replay", str(nan)], replay_nan)
    assert_no_more_poses_than_clean(replay_clean, replay_nan, stderr)


def test_imu_that_fails_for_5_s_and_recovers_resumes_the_walk(stridefixd, default_walk, clean, tmp_path):
    """The daemon's side of a failed IMU in the reliability bench: refused samples counted, no pose
    while the IMU is out, the walk the gap hid bridged, poses and steps again once it is back."""
    candump = tmp_path / "out5s.candump"
    imu_stuck_at_full_scale(default_walk["dir"] / "board.candump", candump, until_s=FAIL_AT_S + 5.0)
    log = tmp_path / "out5s.lcmlog"
    stderr = run(stridefixd, ["-i", str(candump)], log)
    assert "samples refused: 500 out of range" in stderr and "1 walk gaps bridged" in stderr, stderr

    def pdr_poses(path: Path) -> list:
        return [pose_t.decode(e.data) for e in lcm.EventLog(str(path), "r") if e.channel == "POSE_PDR_ONLY"]

    want, got = pdr_poses(clean["log"]), pdr_poses(log)
    out_from, out_until = clean["fail_us"], clean["fail_us"] + 5_000_000
    assert not [p for p in got if out_from + 1_000_000 <= p.t_us < out_until]  # nothing new to say
    assert got[-1].t_us == want[-1].t_us  # poses again to the end
    # the bridge credits distance, not STEP records: about 9 steps of 5 s are not counted (as a silence)
    assert abs(got[-1].step_count - want[-1].step_count) <= 12
    assert math.hypot(got[-1].x_m - want[-1].x_m, got[-1].y_m - want[-1].y_m) < 3.0
