"""The msindoor importer: handmade trace with known content, and one real trace."""

from __future__ import annotations

import math
import warnings

import lcm
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import imu_t, truth_t, wifi_scan_t
from stridefix_analyzer.datasets import msindoor, msindoor_parse
from stridefix_analyzer.datasets.lines import MalformedLineWarning
from stridefix_analyzer.datasets.protocol import NothingValidError
from stridefix_analyzer.datasets.rawwalk import bssid_to_int
from stridefix_analyzer.io.logread import read_logs


def _import(trace, tmp_path, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        summary = msindoor.DATASET.import_walk(trace, tmp_path / "out.lcmlog", **kw)
    return summary, [str(w.message) for w in caught if w.category is MalformedLineWarning]


def test_handmade_counts_and_summary(handmade_trace, tmp_path):
    s, _ = _import(handmade_trace, tmp_path)
    assert s["messages"] == {"IMU": 3, "MAG": 2, "WIFI": 2, "BLE": 0, "TRUTH": 2}
    assert s["waypoints"] == 2
    assert s["skipped_lines"] == 4
    assert s["ignored_lines_by_type"] == {"TYPE_ACCELEROMETER_UNCALIBRATED": 1}
    assert s["floor_name"] == "B1" and s["floor"] == -1
    assert s["duration_s"] == pytest.approx(8.0)  # 1000 ms .. 9000 ms
    assert s["wifi_aps_stale_dropped"] == 1 and s["wifi_aps_duplicate_dropped"] == 1
    assert s["wifi_aps_written"] == 3
    assert s["events"] == 3 + 2 + 2 + 2


def test_handmade_malformed_lines_warn_with_file_and_line(handmade_trace, tmp_path):
    s, warned = _import(handmade_trace, tmp_path)
    assert [d["line"] for d in s["skipped"]] == [9, 10, 11, 12]
    assert len(warned) == 4
    for line_no, text in zip([9, 10, 11, 12], warned):
        assert f"{handmade_trace}:{line_no}:" in text
    assert "6 fields" in warned[0] or "4 fields" in warned[0]
    assert "run together" in warned[2]


def test_handmade_imu_pairs_gyro_interpolated_to_accel_times(handmade_trace, tmp_path):
    _import(handmade_trace, tmp_path)
    imu = read_logs([tmp_path / "out.lcmlog"]).table("IMU")
    assert imu["t_us"].tolist() == [1_000_000, 1_020_000, 1_040_000]
    assert imu["seq"].tolist() == [0, 1, 2]
    assert_allclose(imu["accel_x_mps2"], [0.1, 0.3, 0.5], atol=1e-12)
    assert_allclose(imu["accel_z_mps2"], [9.8, 9.6, 9.4], atol=1e-12)
    # gyro x: 0 at 1000 ms, 0.3 at 1030 ms, 0.5 at 1050 ms -> 0, 0.2, 0.4 at the accel times
    assert_allclose(imu["gyro_x_radps"], [0.0, 0.2, 0.4], atol=1e-12)
    assert_allclose(imu["gyro_y_radps"], [-0.1, -0.1, -0.1], atol=1e-12)


def test_handmade_wifi_scans_grouped_cached_dropped(handmade_trace, tmp_path):
    _import(handmade_trace, tmp_path)
    scans = [
        wifi_scan_t.decode(e.data)
        for e in lcm.EventLog(str(tmp_path / "out.lcmlog"), "r")
        if e.channel == "WIFI"
    ]
    assert [m.t_us for m in scans] == [5_000_000, 8_000_000]
    first, second = scans
    # 5000 ms: aa:..:02 was last seen 3.5 s before the scan -> cached, dropped
    assert first.n_ap == 2
    assert sorted(first.bssid) == [0x0A0B0C0D0E0F, 0xAABBCCDDEE01]
    by_bssid = dict(zip(first.bssid, zip(first.rssi_dbm, first.freq_mhz)))
    assert by_bssid[0xAABBCCDDEE01] == (-50.0, 2412)
    assert by_bssid[0x0A0B0C0D0E0F] == (-61.0, 2437)
    # 8000 ms: the same BSSID twice -> the freshest entry (last seen 7900 ms) is kept
    assert second.n_ap == 1 and list(second.rssi_dbm) == [-52.0]


@pytest.mark.parametrize("max_age_s, n_first_scan", [(3.0, 2), (4.0, 3), (0.05, 1)])
def test_wifi_age_limit_is_a_parameter(handmade_trace, tmp_path, max_age_s, n_first_scan):
    with pytest.warns(MalformedLineWarning, match="4 in all"):
        trace = msindoor.DATASET.read(handmade_trace, max_wifi_age_s=max_age_s, max_line_warnings=0)
    assert len(trace.scan(0)["bssid"]) == n_first_scan


def test_handmade_waypoints_become_truth_in_time_order(handmade_trace, tmp_path):
    _import(handmade_trace, tmp_path)
    events = list(lcm.EventLog(str(tmp_path / "out.lcmlog"), "r"))
    times = [e.timestamp for e in events]
    assert times == sorted(times)
    truth = [truth_t.decode(e.data) for e in events if e.channel == "TRUTH"]
    assert [(m.t_us, m.x_m, m.y_m, m.floor) for m in truth] == [
        (1_000_000, 1.0, 2.0, -1),
        (9_000_000, 4.0, 6.0, -1),
    ]
    assert all(
        math.isnan(m.heading_rad) and m.step_count == -1 and m.source == truth_t.SOURCE_WAYPOINT
        for m in truth
    )
    # event timestamp = the message's t_us
    for e in events:
        if e.channel == "IMU":
            assert imu_t.decode(e.data).t_us == e.timestamp


@pytest.mark.parametrize(
    "name, index",
    [("F1", 0), ("F2", 1), ("F10", 9), ("B1", -1), ("B2", -2), ("1F", 0), ("2B", -2), ("L3", 2), ("G", 0)],
)
def test_floor_index(name, index):
    assert msindoor_parse.floor_index(name) == index


@pytest.mark.parametrize("name", ["", "F0", "roof", "F1.5"])
def test_floor_index_rejects(name):
    with pytest.raises(ValueError):
        msindoor_parse.floor_index(name)


def test_bssid_to_int():
    assert bssid_to_int("a8:0c:ca:05:9f:74") == 0xA80CCA059F74
    with pytest.raises(ValueError):
        bssid_to_int("a8:0c:ca:05:9f")


def test_missing_file_raises_naming_it(tmp_path):
    missing = tmp_path / "nope.txt"
    with pytest.raises(msindoor_parse.TraceReadError, match="nope.txt: no such file"):
        msindoor.DATASET.read(missing)


def test_unknown_floor_name_raises_unless_given(tmp_path):
    path = tmp_path / "roof.txt"
    path.write_text(
        "#\tFloorName:Roof\n1000\tTYPE_WAYPOINT\t1\t2\n1000\tTYPE_ACCELEROMETER\t0\t0\t9.8\t3\n",
        encoding="utf-8",
    )
    with pytest.raises(msindoor_parse.TraceHeaderError, match="roof.txt"):
        msindoor.DATASET.read(path)
    walk = msindoor.DATASET.read(path, floor=7)
    assert walk.meta["floor"] == 7 and walk.truth["floor"].tolist() == [7]


@pytest.mark.parametrize("floor_name", ["Roof", "F32769", "F" + "9" * 400, ""])
def test_without_a_sensor_record_nothing_valid_comes_before_the_floor(tmp_path, floor_name):
    """Regression: an empty, PNG or UTF-16 trace has no FloorName either, and import said "no floor
    index" (exit 2); not one sensor record is what is wrong with it (NothingValidError, exit 3). A
    floor beyond an int16 (truth_t.floor) is refused as a header error, never an OverflowError."""
    path = tmp_path / "waypoints.txt"
    path.write_text(f"#\tFloorName:{floor_name}\n1000\tTYPE_WAYPOINT\t1\t2\n", encoding="utf-8")
    with pytest.raises(NothingValidError, match="waypoints.txt: nothing valid in the input"):
        msindoor.DATASET.read(path)
    path.write_text(path.read_text() + "1000\tTYPE_ACCELEROMETER\t0\t0\t9.8\t3\n", encoding="utf-8")
    with pytest.raises(msindoor_parse.TraceHeaderError, match="no floor index"):
        msindoor.DATASET.read(path)


def test_many_malformed_lines_are_summed_up(tmp_path):
    path = tmp_path / "junk.txt"
    path.write_text("#\tFloorName:F1\n" + "1000\tTYPE_GYROSCOPE\tx\n" * 50, encoding="utf-8")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        trace = msindoor.DATASET.read(path)
    assert len(trace.skipped) == 50
    assert len(caught) == msindoor_parse.MAX_LINE_WARNINGS + 1
    assert "30 more malformed line(s)" in str(caught[-1].message)


def test_cli_imports_each_trace_and_names_missing_one(handmade_trace, tmp_path, cli):
    out = tmp_path / "logs"
    proc = cli("import", "msindoor", str(handmade_trace), str(tmp_path / "missing.txt"), "--out", str(out))
    assert proc.returncode == 2
    assert (out / "handmade.lcmlog").is_file()
    assert "missing.txt: no such file" in proc.stderr
    assert f"{handmade_trace}:9:" in proc.stderr  # the malformed-line warning
    assert "[1/2]" in proc.stderr


# --- one real trace ------------------------------------------------------------------------------


def _count_type(path, kind: str) -> int:
    with open(path, encoding="utf-8") as f:
        return sum(1 for line in f if line.split("\t")[1:2] == [kind])


def test_real_trace(real_trace, tmp_path):
    s, warned = _import(real_trace, tmp_path)
    assert warned == []
    data = read_logs([tmp_path / "out.lcmlog"])
    imu = data.table("IMU")
    t = imu["t_us"]
    assert np.all(np.diff(t) > 0)
    rate_hz = 1e6 / np.median(np.diff(t))
    assert 45 <= rate_hz <= 55
    assert len(imu) == _count_type(real_trace, "TYPE_ACCELEROMETER")
    mag = data.table("MAG")
    assert 45 <= 1e6 / np.median(np.diff(mag["t_us"])) <= 55
    truth = data.table("TRUTH")
    assert len(truth) == s["waypoints"] == _count_type(real_trace, "TYPE_WAYPOINT")
    assert set(truth["floor"].tolist()) == {1}  # FloorName F2
    wifi = data.table("WIFI")
    assert len(wifi) >= 10 and np.all(wifi["n_ap"] > 0)
    # accelerometer magnitude of a phone held flat: about g on average
    acc = np.linalg.norm(np.column_stack([imu[f"accel_{a}_mps2"] for a in "xyz"]), axis=1)
    assert 9.0 < acc.mean() < 10.6


def test_default_wifi_age_limit_is_2_s(tmp_path):
    # an entry last seen more than ~2 s before its scan is a cached result: dropped
    assert msindoor.DATASET.defaults.max_wifi_age_s == 2.0
    path = tmp_path / "ages.txt"
    path.write_text(
        "#\tFloorName:F1\n"
        "5000\tTYPE_WIFI\ta\taa:bb:cc:dd:ee:01\t-50\t2412\t3100\n"  # 1.9 s: kept
        "5000\tTYPE_WIFI\tb\taa:bb:cc:dd:ee:02\t-60\t2412\t2500\n",  # 2.5 s: cached
        encoding="utf-8",
    )
    trace = msindoor.DATASET.read(path)
    assert trace.scan(0)["bssid"].tolist() == [0xAABBCCDDEE01]
    assert trace.stats["wifi_aps_stale_dropped"] == 1
