"""End to end, the absolute sources besides Wi-Fi: a candump with BLE_ADV, LANDMARK and GNSS frames
(cantools-encoded from board.dbc) replayed through stridefixd with a site that has a geo-reference
and beacons gives BLE, LANDMARK and GNSS channels in the log, FIX records of METHOD_BLE,
METHOD_LANDMARK and METHOD_GNSS, HEALTH counts per source, and `stridefix analyze` counts the FIX
records per scheme and per source; the raw-sensor log replayed (lcmlog:) gives the same FIX records."""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import cantools
import lcm
import numpy as np
import pytest
from stridefix import fix_t, truth_t
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.io.results import read_analyze_metrics
from stridefix_analyzer.io.sitefile import new_site, write_site
from stridefix_analyzer.schemes import FUSION_SCHEMES

NAMES = tuple(s.name for s in FUSION_SCHEMES)  # the schemes that judge fixes (not the controller)

REPO = Path(__file__).resolve().parents[3]
DBC = REPO / "firmware" / "board.dbc"
T0_MS = 50_000
HOST0_S = 1_700_000_000.0
DURATION_S = 6
ORIGIN = (48.1, 11.5, 500.0)  # lat, lon [deg], alt [m]
EARTH_R_M = 6_378_137.0
#: beacons (MAC, x, y) on floor 0, all within ble.max_range_m (15 m) of where the walker stands [m]
BEACONS = [(0xE078A33D0001, 0.0, 0.0), (0xE078A33D0002, 20.0, 0.0), (0xE078A33D0003, 0.0, 16.0)]
STAND_XY = (8.0, 6.0)
LANDMARK_XY = (8.5, 6.5)
RSSI_1M_DBM, PATH_LOSS_N = -59.0, 2.0


def _site(path: Path) -> None:
    fields = dict(
        name="sources-test",
        has_geo=True,
        origin_lat_deg=ORIGIN[0],
        origin_lon_deg=ORIGIN[1],
        ap_bssid=[0x001122334455],
        cell_size_m=2.0,
        rp_x_m=[0.0, 10.0],
        rp_y_m=[0.0, 10.0],
        rp_floor=[0, 0],
        rp_scans=[3, 3],
        entry_ap=[0, 0],
        entry_rp=[0, 1],
        entry_mean_dbm=[-50.0, -70.0],
        entry_std_db=[3.0, 3.0],
        entry_count=[3, 3],
    )
    fields.update(
        origin_alt_m=ORIGIN[2],
        geo_rotation_deg=0.0,
        beacon_id=[b[0] for b in BEACONS],
        beacon_x_m=[b[1] for b in BEACONS],
        beacon_y_m=[b[2] for b in BEACONS],
        beacon_floor=[0] * len(BEACONS),
        beacon_rssi_1m_dbm=[math.nan] * len(BEACONS),
        ble_rssi_1m_dbm=RSSI_1M_DBM,
        ble_path_loss_exponent=PATH_LOSS_N,
        ble_range_sigma_db=4.0,
    )
    write_site(path, new_site(**fields))


def _candump(path: Path) -> dict[str, int]:
    """DURATION_S of a still board: BOARD_TIME 1 Hz, IMU 100 Hz, GNSS 1 Hz at STAND_XY (accuracy
    5 m), one BLE_ADV per beacon every 200 ms at the path-loss level of its distance, one LANDMARK
    at 3 s. Returns the frames sent by name."""
    db = cantools.database.load_file(str(DBC))
    frames: list[tuple[float, str, dict]] = []
    lat = ORIGIN[0] + math.degrees(STAND_XY[1] / EARTH_R_M)
    lon = ORIGIN[1] + math.degrees(STAND_XY[0] / (EARTH_R_M * math.cos(math.radians(ORIGIN[0]))))
    for ms in range(0, DURATION_S * 1000, 10):
        t = T0_MS + ms
        if ms % 1000 == 0:
            frames.append((ms, "BOARD_TIME", {"time_ms": t, "boot_id": 1}))
            frames.append((ms + 1, "GNSS_INFO", {"time_ms": t, "altitude": ORIGIN[2], "accuracy": 5.0}))
            frames.append((ms + 1, "GNSS_POSITION", {"latitude": round(lat, 7), "longitude": round(lon, 7)}))
        seq = (ms // 10) % 256
        frames.append(
            (
                ms,
                "IMU_ACCEL",
                {"accel_x": 0.0, "accel_y": 0.0, "accel_z": 9.81, "seq": seq, "t_lo_ms": t % 256},
            )
        )
        frames.append(
            (ms, "IMU_GYRO", {"gyro_x": 0.0, "gyro_y": 0.0, "gyro_z": 0.0, "seq": seq, "t_lo_ms": t % 256})
        )
        if ms % 200 == 100:
            for i, (mac, bx, by) in enumerate(BEACONS):
                d = max(1.0, math.hypot(STAND_XY[0] - bx, STAND_XY[1] - by))
                rssi = round(RSSI_1M_DBM - 10 * PATH_LOSS_N * math.log10(d))
                frames.append((ms + i, "BLE_ADV", {"beacon_id": mac, "rssi": rssi, "t_lo_ms": (t + i) % 256}))
        if ms == 3000:
            lm = {"x": LANDMARK_XY[0], "y": LANDMARK_XY[1], "floor": 0, "t_lo_ms": t % 256}
            frames.append((ms + 5, "LANDMARK", lm))
    frames.sort(key=lambda f: f[0])
    lines, sent = [], {}
    for ms, name, sig in frames:
        msg = db.get_message_by_name(name)
        data = msg.encode(sig)
        lines.append(f"({HOST0_S + ms / 1000:.6f}) can0 {msg.frame_id:03X}#{data.hex().upper()}\n")
        sent[name] = sent.get(name, 0) + 1
    path.write_text("".join(lines))
    return sent


@pytest.fixture(scope="module")
def sources_run(tmp_path_factory, stridefixd, cli) -> dict:
    """GIVEN the candump and the site, WHEN stridefixd replays it."""

    d = tmp_path_factory.mktemp("sources")
    sent = _candump(d / "board.candump")
    _site(d / "site.sfsite")
    proc = subprocess.run(
        [
            str(stridefixd),
            "--input",
            str(d / "board.candump"),
            "--site",
            str(d / "site.sfsite"),
            "--log",
            str(d / "run.lcmlog"),
        ],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    return {"dir": d, "sent": sent, "stderr": proc.stderr, "data": read_logs([d / "run.lcmlog"])}


def test_fast_reader_reads_the_log_as_lcm_eventlog_does(sources_run, assert_reads_alike):
    # BLE (variable-length arrays, decoded one by one), GNSS, LANDMARK and their FIX records
    data = assert_reads_alike([sources_run["dir"] / "run.lcmlog"])
    assert {"BLE", "GNSS", "LANDMARK", "FIX"} <= set(data.tables)


def test_log_carries_the_new_raw_inputs(sources_run):
    """THEN the log has one LANDMARK event, a GNSS event per fix and one BLE scan per 1 s window
    (ble.window_ms), each beacon once in it at the level sent."""
    data, sent = sources_run["data"], sources_run["sent"]
    assert data.messages["LANDMARK"] == sent["LANDMARK"] == 1
    assert data.messages["GNSS"] == sent["GNSS_POSITION"] == DURATION_S
    # advertisements from 100 ms to DURATION_S - 0.1 s: windows [0.1, 1.1), [1.1, 2.1), ... and the last
    # one flushed at the end
    assert data.messages["BLE"] == DURATION_S
    lm = data.table("LANDMARK")
    assert lm["x_m"][0] == pytest.approx(LANDMARK_XY[0], abs=0.005)
    assert lm["y_m"][0] == pytest.approx(LANDMARK_XY[1], abs=0.005)
    assert lm["accuracy_m"][0] == pytest.approx(0.3)  # landmark.accuracy_m
    assert lm["t_us"][0] == (T0_MS + 3000) * 1000
    h = data.health
    assert h["ble_scans"] == DURATION_S and h["landmark_events"] == 1
    assert h["ble_adverts"] == sent["BLE_ADV"] and h["ble_dropped"] == 0
    assert h["fixes_offered_ble"] == DURATION_S
    assert h["fixes_offered_gnss"] == DURATION_S
    assert h["fixes_offered_landmark"] == 1 and h["fixes_made_landmark"] == 1
    assert (
        "sources: 6 BLE scans (90 advertisements, 0 dropped from full windows), 1 LANDMARK"
        in sources_run["stderr"]
    )
    assert "fixes made of offered: Wi-Fi 0 of 0, GNSS" in sources_run["stderr"]
    assert "landmark 1 of 1" in sources_run["stderr"]


def test_landmark_fix_is_judged_by_every_scheme(sources_run):
    """THEN the landmark is one FIX record per scheme, METHOD_LANDMARK, at the landmark's position."""
    fix = sources_run["data"].table("FIX")
    sel = fix["method"] == fix_t.METHOD_LANDMARK
    assert sorted(fix["scheme"][sel].tolist()) == list(range(len(NAMES)))
    assert np.allclose(fix["x_m"][sel], LANDMARK_XY[0], atol=0.005)
    assert np.all(fix["t_us"][sel] == (T0_MS + 3000) * 1000)


def test_gnss_and_ble_fixes_with_a_v2_site(sources_run):
    """THEN GNSS fixes (through the geo-reference) and BLE fixes (ranges to the beacons) are FIX
    records of METHOD_GNSS and METHOD_BLE near where the walker stands, and HEALTH counts them made."""
    fix = sources_run["data"].table("FIX")
    h = sources_run["data"].health
    for method, made in ((fix_t.METHOD_GNSS, "fixes_made_gnss"), (fix_t.METHOD_BLE, "fixes_made_ble")):
        sel = fix["method"] == method
        assert sel.sum() >= len(NAMES), method
        assert h[made] > 0
    gnss = fix["method"] == fix_t.METHOD_GNSS
    assert np.allclose(fix["x_m"][gnss], STAND_XY[0], atol=0.5)
    assert np.allclose(fix["y_m"][gnss], STAND_XY[1], atol=0.5)
    ble = (fix["method"] == fix_t.METHOD_BLE) & (fix["accuracy_m"] > 0)
    err = np.hypot(fix["x_m"][ble] - STAND_XY[0], fix["y_m"][ble] - STAND_XY[1])
    assert np.median(err) < 3.0


def test_analyze_counts_fixes_per_source(sources_run, cli):
    """WHEN `stridefix analyze` reads the log (with a truth log of the still walker), THEN
    metrics.json counts the FIX records per scheme and method, the same as the log holds."""
    d = sources_run["dir"]
    fix = sources_run["data"].table("FIX")
    truth = d / "truth.lcmlog"
    _truth_log(truth)
    proc = cli("analyze", str(d / "run.lcmlog"), str(truth), "--out", str(d / "analyze"))
    assert proc.returncode == 0, proc.stderr
    assert "fix sources (FIX records per scheme and source)" in proc.stdout
    doc = read_analyze_metrics(d / "analyze" / "metrics.json")
    fs = doc["fix_sources"]
    for s, name in enumerate(NAMES):
        lm = fs[name]["landmark"]
        assert lm["offered"] == int(np.sum((fix["scheme"] == s) & (fix["method"] == fix_t.METHOD_LANDMARK)))
        assert lm["accepted"] + lm["rejected"] == lm["offered"]
        assert sum(lm["rejected_by_reason"].values()) == lm["rejected"]
    total = sum(v["offered"] for per in fs.values() for v in per.values())
    assert total == len(fix["scheme"])


def _truth_log(path: Path) -> None:
    """TRUTH at 10 Hz: the walker still at STAND_XY on floor 0."""

    log = lcm.EventLog(str(path), "w", overwrite=True)
    for ms in range(0, DURATION_S * 1000, 100):
        m = truth_t()
        m.t_us = (T0_MS + ms) * 1000
        m.x_m, m.y_m = STAND_XY
        m.floor, m.heading_rad, m.step_count, m.source = 0, 0.0, 0, truth_t.SOURCE_SIMULATION
        log.write_event(m.t_us, "TRUTH", m.encode())
    log.close()


def test_lcm_replay_feeds_the_same_fixes(sources_run, stridefixd):
    """WHEN the firmware's own log (its raw BLE, LANDMARK and GNSS inputs) is replayed through
    lcmlog:, THEN the same FIX records come out, field by field, and the same HEALTH source counts."""
    d = sources_run["dir"]
    cmd = [str(stridefixd), "--input", f"lcmlog:{d / 'run.lcmlog'}", "--site", str(d / "site.sfsite")]
    proc = subprocess.run([*cmd, "--log", str(d / "replay.lcmlog")], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    again = read_logs([d / "replay.lcmlog"])
    a, b = sources_run["data"].table("FIX"), again.table("FIX")
    assert len(b) == len(a) > 0
    for col in ("t_us", "method", "scheme", "x_m", "y_m", "accepted", "reason"):
        assert np.array_equal(a[col], b[col]), col
    for key in ("ble_scans", "landmark_events", "gnss_fixes", "fixes_offered_ble", "fixes_made_landmark"):
        assert again.health[key] == sources_run["data"].health[key], key
