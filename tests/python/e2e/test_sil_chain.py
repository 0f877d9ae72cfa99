"""End to end: simulator -> candump -> stridefixd -> LCM log -> analyzer.

GIVEN the default SIL walk, WHEN the real firmware binary replays its candump log, THEN every IMU
sample the simulator sent is in the LCM log, nothing failed to decode, the step count is within 3 %
of the truth, and the analyzer scores the log. Bad input lines are counted and skipped, not fatal."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import lcm
import pytest
from stridefix import health_t
from stridefix_analyzer.io.results import read_analyze_metrics


def run_stridefixd(stridefixd: Path, walk_dir: Path, log: Path, candump: Path | None = None, stdin=None):
    cmd = [
        str(stridefixd),
        "--input",
        "-" if stdin is not None else str(candump or walk_dir / "board.candump"),
        "--log",
        str(log),
        "--config",
        str(walk_dir / "init_truth.ini"),
    ]
    return subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=300)


def channel_counts(log: Path) -> tuple[dict[str, int], health_t | None]:
    counts: dict[str, int] = {}
    last_health = None
    for event in lcm.EventLog(str(log), "r"):
        counts[event.channel] = counts.get(event.channel, 0) + 1
        if event.channel == "HEALTH":
            last_health = health_t.decode(event.data)
    return counts, last_health


@pytest.fixture(scope="module")
def replay(stridefixd, default_walk, tmp_path_factory):
    """WHEN stridefixd replays the default walk's candump log."""
    log = tmp_path_factory.mktemp("replay") / "stridefixd.lcmlog"
    proc = run_stridefixd(stridefixd, default_walk["dir"], log)
    assert proc.returncode == 0, proc.stderr
    counts, health = channel_counts(log)
    return {"log": log, "proc": proc, "counts": counts, "health": health}


def test_fast_reader_reads_the_log_as_lcm_eventlog_does(replay, default_walk, assert_reads_alike):
    # the numpy reader on the default walk's replay (IMU, MAG, BARO, WIFI, STEP, POSE, HEALTH, CONFIG)
    # and its truth: the same tables, counts and warnings as record by record
    data = assert_reads_alike([replay["log"], default_walk["dir"] / "truth.lcmlog"])
    assert len(data.tables["IMU"]) == default_walk["summary"]["imu_samples"]


def test_every_imu_sample_is_logged(replay, default_walk):
    assert replay["counts"]["IMU"] == default_walk["summary"]["imu_samples"]
    assert replay["health"].imu_samples == default_walk["summary"]["imu_samples"]


def test_other_streams_are_logged(replay, default_walk):
    s = default_walk["summary"]
    assert replay["counts"]["MAG"] == s["mag_samples"]
    assert replay["counts"]["BARO"] == s["baro_samples"]
    assert replay["counts"]["WIFI"] == s["wifi_scans"]
    assert replay["counts"]["CONFIG"] == 1
    assert replay["counts"]["HEALTH"] >= s["duration_s"] - 2  # about one a second of board time


def test_no_decode_errors(replay):
    h = replay["health"]
    assert (h.bad_syntax, h.unknown_id, h.bad_length, h.decode_errors) == (0, 0, 0, 0)
    assert (h.seq_gaps, h.unsynced, h.imu_unpaired, h.wifi_incomplete, h.log_drops) == (0, 0, 0, 0, 0)


def test_step_count_within_3_percent(replay, default_walk):
    truth_steps = default_walk["summary"]["steps"]
    assert truth_steps > 100
    assert replay["counts"]["STEP"] == pytest.approx(truth_steps, rel=0.03)


def test_exit_summary_names_the_counts(replay, default_walk):
    err = replay["proc"].stderr
    m = re.search(r"(\d+) IMU", err)
    assert m and int(m.group(1)) == default_walk["summary"]["imu_samples"], err
    assert "0 bad syntax" in err and "0 decode errors" in err


def test_stdin_pipe_gives_the_same_log(stridefixd, default_walk, replay, tmp_path):
    candump = (default_walk["dir"] / "board.candump").read_text()
    log = tmp_path / "pipe.lcmlog"
    proc = run_stridefixd(stridefixd, default_walk["dir"], log, stdin=candump)
    assert proc.returncode == 0, proc.stderr

    # Event timestamps come from the candump lines, so the same input gives the same events; only
    # HEALTH differs, as it carries run-time measurements (loop timing, log writer progress).
    def events(path):
        return [
            (e.timestamp, e.channel, e.data) for e in lcm.EventLog(str(path), "r") if e.channel != "HEALTH"
        ]

    assert events(log) == events(replay["log"])


def test_lcm_logplayer_reads_the_log(replay):
    player = shutil.which("lcm-logplayer")
    if player is None:
        pytest.fail("lcm-logplayer not installed (liblcm-bin)")
    proc = subprocess.run(
        [player, "-v", "-s", "1000000", "-l", "memq://", str(replay["log"])],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    total = sum(replay["counts"].values())
    played = len(re.findall(r"^\s*\d+.*IMU", proc.stdout + proc.stderr, flags=re.M))
    assert played == replay["counts"]["IMU"], (total, (proc.stdout + proc.stderr)[:500])


def test_analyzer_scores_the_log(replay, default_walk, tmp_path, cli):
    proc = cli(
        "analyze", str(replay["log"]), str(default_walk["dir"] / "truth.lcmlog"), "--out", str(tmp_path)
    )
    assert proc.returncode == 0, proc.stderr
    metrics = read_analyze_metrics(tmp_path / "metrics.json")
    err = metrics["position_error_m"]
    assert err["n"] > 100
    assert 0.0 <= err["median"] <= err["p95"] <= err["max"]
    assert metrics["steps"]["truth"] == default_walk["summary"]["steps"]
    assert abs(metrics["steps"]["error_pct"]) <= 3.0
    proc = cli("report", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert "data:image/png;base64," in (tmp_path / "report.html").read_text()


def test_bad_lines_are_counted_and_skipped(stridefixd, default_walk, tmp_path):
    """GIVEN the walk's candump with garbage, an unknown id and a truncated frame spliced in."""
    lines = (default_walk["dir"] / "board.candump").read_text().splitlines(keepends=True)
    t = lines[500].split(")")[0] + ")"
    bad = [
        "this is not a candump line\n",
        f"{t} can0 7FF#0011223344556677\n",  # unknown id
        f"{t} can0 100#001122\n",  # IMU_ACCEL truncated to 3 bytes
        f"{t} can0 100#0011X2\n",  # bad hex
    ]
    spliced = lines[:501] + bad + lines[501:]
    candump = tmp_path / "bad.candump"
    candump.write_text("".join(spliced))
    log = tmp_path / "bad.lcmlog"
    proc = run_stridefixd(stridefixd, default_walk["dir"], log, candump=candump)
    assert proc.returncode == 0, proc.stderr
    counts, h = channel_counts(log)
    assert (h.bad_syntax, h.unknown_id, h.bad_length) == (2, 1, 1)
    assert counts["IMU"] == default_walk["summary"]["imu_samples"]  # nothing else lost
    assert f"bad.candump:{502}:" in proc.stderr  # the message names file and line
    assert "2 bad syntax, 1 unknown id, 1 truncated" in proc.stderr


def test_missing_input_exits_2(stridefixd, tmp_path):
    proc = subprocess.run(
        [str(stridefixd), "--input", str(tmp_path / "nope.candump"), "--no-log"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert "nope.candump" in proc.stderr


def test_lost_frames_and_board_time_wrap(stridefixd, tmp_path, cli):
    """GIVEN a walk whose board clock passes 2**32 ms and whose CAN link loses 2 % of frames,
    WHEN stridefixd replays it, THEN every sample that arrived whole is logged with its exact board
    time, the lost ones are counted as gaps, and steps still come out within 3 %."""
    common = ["--duration-s", "60", "--board-time-start-ms", str(2**32 - 30_000), "--seed", "7"]
    clean, lossy = tmp_path / "clean", tmp_path / "lossy"
    for out, extra in ((clean, []), (lossy, ["--loss-rate", "0.02"])):
        proc = cli("sim", "--out", str(out), *common, *extra)
        assert proc.returncode == 0, proc.stderr
    sent = json.loads((clean / "sim_summary.json").read_text())
    got = json.loads((lossy / "sim_summary.json").read_text())
    assert got["frames_dropped"] > 100

    log = tmp_path / "lossy.lcmlog"
    proc = run_stridefixd(stridefixd, lossy, log)
    assert proc.returncode == 0, proc.stderr
    counts, h = channel_counts(log)
    assert counts["IMU"] == got["imu_samples"]
    assert counts["MAG"] == got["mag_samples"]
    assert counts["BARO"] == got["baro_samples"]
    lost = sum(sent[k] - got[k] for k in ("imu_samples", "mag_samples", "baro_samples"))
    # Samples lost before a stream's first or after its last received sample cannot be seen.
    assert lost - 6 <= h.seq_gaps <= lost
    assert (h.bad_syntax, h.unknown_id, h.bad_length, h.unsynced) == (0, 0, 0, 0)

    # The board times of the received IMU samples are exactly those of the clean run (to 1 ms),
    # straight through the 32-bit wrap.
    from stridefix import imu_t

    clean_log = tmp_path / "clean.lcmlog"
    assert run_stridefixd(stridefixd, clean, clean_log).returncode == 0
    t_clean = {
        imu_t.decode(e.data).seq: imu_t.decode(e.data).t_us
        for e in lcm.EventLog(str(clean_log), "r")
        if e.channel == "IMU"
    }
    t_lossy = [
        (imu_t.decode(e.data).seq, imu_t.decode(e.data).t_us)
        for e in lcm.EventLog(str(log), "r")
        if e.channel == "IMU"
    ]
    assert max(t for _, t in t_lossy) > 2**32 * 1000  # past the wrap
    assert all(t_clean[seq] == t for seq, t in t_lossy)
    assert counts["STEP"] == pytest.approx(got["steps"], rel=0.03)


def test_the_analyzer_knows_every_channel_the_firmware_writes(replay):
    # io/channels.py maps channel names to the generated LCM types; a channel the firmware starts
    # writing (or a type whose hash changed without a rebuild) must not be skipped silently
    from stridefix_analyzer.io.logread import read_logs

    data = read_logs([replay["log"]])  # every known channel decoded
    assert data.unknown_channels == {} and data.decode_errors == {}
    assert {"IMU", "MAG", "BARO", "WIFI", "STEP", "POSE", "HEALTH", "CONFIG"} <= set(replay["counts"])
