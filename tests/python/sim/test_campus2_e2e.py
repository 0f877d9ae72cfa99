"""End to end, the campus2 walk through the real firmware (the multi-scheme controller's SIL campus): GIVEN ``stridefix sim --scenario
campus2`` (seed 1), WHEN stridefixd replays its candump with the true start pose, THEN every IMU sample,
GNSS fix, BLE advertisement window and landmark read the simulator sent is in the LCM log without a
decode error, the step count is within 3 % of the truth, the PDR pose's barometric floor follows the
truth over three floors (stairs and both elevator rides), and sim_summary.json carries the contexts
and the transitions, whose truth times agree with the truth log."""

from __future__ import annotations

import json
import subprocess

import lcm
import numpy as np
import pytest
import stridefix_channels
from stridefix import health_t, pose_t, truth_t

FLOOR_HIT_MIN = 0.97  # PDR + barometer alone; the stairs and rides are a few % of the walk
SCHEME_POSE_CHANNELS = set(stridefix_channels.POSE_SCHEME_CHANNELS.values())  # POSE_PDR_ONLY, ...


@pytest.fixture(scope="module")
def replay(sim_run, stridefixd):
    out = sim_run("--scenario", "campus2", "--seed", "1")
    log = out / "stridefixd.lcmlog"
    cmd = [str(stridefixd), "--input", str(out / "board.candump"), "--log", str(log)]
    proc = subprocess.run(
        [*cmd, "--config", str(out / "init_truth.ini")], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    counts: dict[str, int] = {}
    health, poses, truth = None, [], []
    for e in lcm.EventLog(str(log), "r"):
        counts[e.channel] = counts.get(e.channel, 0) + 1
        if e.channel == "HEALTH":
            health = health_t.decode(e.data)
        elif e.channel in SCHEME_POSE_CHANNELS:  # each fusion scheme's own poses
            p = pose_t.decode(e.data)
            poses.append((p.t_us, p.scheme, p.floor))
    for e in lcm.EventLog(str(out / "truth.lcmlog"), "r"):
        t = truth_t.decode(e.data)
        truth.append((t.t_us, t.floor))
    return {
        "dir": out,
        "summary": json.loads((out / "sim_summary.json").read_text()),
        "sources": json.loads((out / "sources.json").read_text()),
        "counts": counts,
        "health": health,
        "pose": np.array(poses, dtype=np.int64),
        "truth": np.array(truth, dtype=np.int64),
    }


def test_every_sample_and_source_is_logged(replay):
    s, c, h = replay["summary"], replay["counts"], replay["health"]
    assert c["IMU"] == s["imu_samples"] and c["BARO"] == s["baro_samples"] and c["WIFI"] == s["wifi_scans"]
    assert c["GNSS"] == s["sources"]["gnss_fixes"] >= 60
    assert c["LANDMARK"] == s["sources"]["landmark_events"] == 3
    assert c["BLE"] >= 60  # one scan message per window with advertisements (B's corridor and room)
    assert (h.bad_syntax, h.unknown_id, h.bad_length, h.decode_errors, h.seq_gaps) == (0, 0, 0, 0, 0)


def test_without_a_site_pdr_only_and_its_copy_on_pose(replay):
    """No site, no fixes: only pdr_only publishes (POSE_PDR_ONLY), and POSE, the primary pose, is its
    copy, one per output."""
    c = replay["counts"]
    assert {ch for ch in c if ch.startswith("POSE")} == {"POSE", "POSE_PDR_ONLY"}
    assert c["POSE"] == c["POSE_PDR_ONLY"] > 1000


def test_step_count_within_3_percent(replay):
    assert replay["counts"]["STEP"] == pytest.approx(replay["summary"]["steps"], rel=0.03)


def test_pdr_floor_follows_the_truth_over_three_floors(replay):
    pose, truth = replay["pose"], replay["truth"]
    pdr = pose[pose[:, 1] == pose_t.SCHEME_PDR_ONLY]
    k = np.clip(np.searchsorted(truth[:, 0], pdr[:, 0]), 0, len(truth) - 1)
    assert set(np.unique(truth[:, 1]).tolist()) == {0, 1, 2}
    assert np.mean(pdr[:, 2] == truth[k, 1]) >= FLOOR_HIT_MIN


def test_summary_transitions_agree_with_the_truth_log(replay):
    s, truth = replay["summary"], replay["truth"]
    assert [(c["kind"], c["building"], c["floor"]) for c in s["contexts"]] == [
        ("outdoor", None, 0),
        ("floor", "A", 0),
        ("floor", "A", 1),
        ("floor", "A", 2),
        ("floor", "B", 0),
    ]
    tr = s["transitions"]
    assert [t["kind"] for t in tr] == ["door", "stairs", "elevator", "elevator", "door", "door"]
    for t in tr:
        # the truth log's floor 0.5 s after the transition is the new context's floor
        k = int(np.searchsorted(truth[:, 0], t["t_us"] + 500_000))
        assert truth[k, 1] == t["to_context"]["floor"]
    # the landmark reads (sources.json) are the door transitions
    doors = [t["t_s"] for t in tr if t["kind"] == "door"]
    np.testing.assert_allclose([e["t_s"] for e in replay["sources"]["landmarks"]], doors, atol=0.02)
