"""BLE (and gsd GNSS) on import: msindoor TYPE_BEACON and gsd BLE4 readings become ble_scan_t
messages on channel BLE, grouped into windows of rawwalk.BLE_WINDOW_S; gsd GNSS fixes reach GNSS on
the app clock. Handmade files with known content, and the real data."""

from __future__ import annotations

import math
import warnings

import lcm
import numpy as np
import pytest
from stridefix import ble_scan_t, gnss_t
from stridefix_analyzer.datasets import gsd, msindoor
from stridefix_analyzer.datasets.rawwalk import BLE_WINDOW_S, ble_scans

from .conftest import GSD, REAL_GSD, REAL_TRACE

_BEACON = "TYPE_BEACON\t9195B3AD-A9D0-4500-85FF-9FB0F65A5201\t0\t0\t-56"


def _ble(path):
    return [ble_scan_t.decode(e.data) for e in lcm.EventLog(str(path), "r") if e.channel == "BLE"]


def _import(dataset, path, out):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return dataset.import_walk(path, out)


def test_window_is_one_second():
    assert BLE_WINDOW_S == 1.0


def test_ble_scans_group_by_window_and_merge_repeats():
    stats: dict = {}
    readings = [
        (2_500_000, 0xA, -70.0),  # out of order: sorted first
        (1_000_000, 0xB, -60.0),
        (1_400_000, 0xA, -80.0),
        (1_900_000, 0xB, -64.0),  # B twice in the first window: mean -62
        (2_000_000, 0xB, -50.0),  # 1.0 s after the window's first reading: a new window
        (3_100_000, 0xC, -90.0),
    ]
    t = ble_scans(readings, stats)
    assert t["scan"].tolist() == [0, 0, 1, 1, 2]
    assert t["t_us"].tolist() == [1_000_000, 1_000_000, 2_000_000, 2_000_000, 3_100_000]
    assert t["beacon_id"].tolist() == [0xA, 0xB, 0xA, 0xB, 0xC]
    assert t["rssi_dbm"].tolist() == [-80.0, -62.0, -70.0, -50.0, -90.0]
    assert stats["ble_readings"] == 6 and stats["ble_scans"] == 3 and stats["ble_beacons"] == 3
    assert stats["ble_repeats_merged"] == 1


def test_msindoor_beacons_become_ble_scans(tmp_path):
    lines = [
        "#\tSiteID:x\tFloorName:F1",
        "1000\tTYPE_ACCELEROMETER\t0.0\t0.0\t9.8\t3",
        f"1100\t{_BEACON}\t-70\t3.1\tE0:78:A3:3E:92:D5\t1100",
        f"1300\t{_BEACON}\t-80\t9.9\tE0:78:A3:3E:99:84\t1300",
        f"1900\t{_BEACON}\t-74\t3.2\tE0:78:A3:3E:92:D5\t1900",
        f"2500\t{_BEACON}\t-66\t2.0\tE0:78:A3:3E:99:84\t2500",
        f"2600\t{_BEACON}\t-66\t2.0\tnot-a-mac\t2600",
        "3000\tTYPE_WAYPOINT\t1.0\t2.0",
    ]
    trace = tmp_path / "t.txt"
    trace.write_text("\n".join(lines) + "\n", encoding="utf-8")
    s = _import(msindoor.DATASET, trace, tmp_path / "out.lcmlog")
    assert s["messages"]["BLE"] == 2
    assert s["ble_readings"] == 4 and s["ble_beacons"] == 2 and s["skipped_lines"] == 1
    scans = _ble(tmp_path / "out.lcmlog")
    assert [m.t_us for m in scans] == [1_100_000, 2_500_000]  # system time used as the Wi-Fi lines'
    assert [m.n for m in scans] == [2, 1]
    assert list(scans[0].beacon_id) == [0xE078A33E92D5, 0xE078A33E9984]
    assert list(scans[0].rssi_dbm) == [-72.0, -80.0]
    assert list(scans[1].beacon_id) == [0xE078A33E9984] and list(scans[1].rssi_dbm) == [-66.0]


def test_gsd_ble4_ibeacon_and_eddystone(tmp_path):
    lines = [
        "ACCE;1.000;5000.000;0.1;0.2;9.8;3",
        "BLE4;2.100;iBeacon;BE:AC:20:23:00:01;-90;0;1;1;11111111-1111-BEAC-2023-111111111111",
        "BLE4;2.600;Eddystone;BE:AC:20:23:00:02;-77;0x0001;3.1;22;100;4",
        "BLE4;2.700;iBeacon;BE:AC:20:23:00:01;-86;0;1;1;11111111-1111-BEAC-2023-111111111111",
        "BLE4;3.200;iBeacon;BE:AC:20:23:00:06;-60;0;1;6;11111111-1111-BEAC-2023-111111111111",
        "BLE4;3.300;Bluetooth;BE:AC:20:23:00:06;-60",
        "GNSS;2.500;1686729679.0000;49.461268;11.111051;347.500;0.000;12.0;0.0;23;21",
        "POSI;3.0000;1;49.460000000000;11.110000000000;0;100",
    ]
    log = tmp_path / "g.txt"
    log.write_text("\n".join(lines) + "\n", encoding="utf-8")
    s = _import(gsd.DATASET, log, tmp_path / "out.lcmlog")
    assert s["messages"]["BLE"] == 2 and s["ble_readings"] == 4 and s["skipped_lines"] == 1
    scans = _ble(tmp_path / "out.lcmlog")
    assert [m.t_us for m in scans] == [2_100_000, 3_200_000]
    assert list(scans[0].beacon_id) == [0xBEAC20230001, 0xBEAC20230002]
    assert list(scans[0].rssi_dbm) == [-88.0, -77.0]
    assert list(scans[1].beacon_id) == [0xBEAC20230006]
    fixes = [
        gnss_t.decode(e.data) for e in lcm.EventLog(str(tmp_path / "out.lcmlog"), "r") if e.channel == "GNSS"
    ]
    assert [f.t_us for f in fixes] == [2_500_000]
    assert (fixes[0].lat_deg, fixes[0].lon_deg, fixes[0].alt_m, fixes[0].accuracy_m) == (
        49.461268,
        11.111051,
        347.5,
        12.0,
    )


def test_real_msindoor_walk_has_beacons(tmp_path):
    if not REAL_TRACE.is_file():
        pytest.skip(f"real msindoor data not found at {REAL_TRACE}")
    with open(REAL_TRACE, encoding="utf-8") as f:
        n_lines = sum(1 for line in f if "\tTYPE_BEACON\t" in line and line.count("\tTYPE_") == 1)
    s = _import(msindoor.DATASET, REAL_TRACE, tmp_path / "out.lcmlog")
    assert s["ble_readings"] == n_lines and n_lines > 20
    scans = _ble(tmp_path / "out.lcmlog")
    assert len(scans) == s["messages"]["BLE"] == s["ble_scans"]
    assert sum(m.n for m in scans) + s["ble_repeats_merged"] == n_lines
    rssi = np.concatenate([m.rssi_dbm for m in scans])
    assert -110 < rssi.min() and rssi.max() < -20
    imu_t = [e.timestamp for e in lcm.EventLog(str(tmp_path / "out.lcmlog"), "r") if e.channel == "IMU"]
    # beacons heard during the walk: on the clock of the other samples
    assert imu_t[0] - 5e6 <= scans[0].t_us and scans[-1].t_us <= imu_t[-1] + 5e6


def test_real_gsd_log_has_ble4_and_gnss(tmp_path):
    if not REAL_GSD.is_file():
        pytest.skip(f"real gsd data not found at {GSD}")
    with open(REAL_GSD, encoding="utf-8") as f:
        n_ble4 = sum(1 for line in f if line.startswith("BLE4;"))
    s = _import(gsd.DATASET, REAL_GSD, tmp_path / "out.lcmlog")
    assert s["ble_readings"] == n_ble4 > 100
    ids = {b for m in _ble(tmp_path / "out.lcmlog") for b in m.beacon_id}
    assert {i & 0xFFFFFFFFFF00 for i in ids} == {0xBEAC20230000}  # BE:AC:20:23:00:xx
    assert s["messages"]["GNSS"] > 100
    fixes = [
        gnss_t.decode(e.data) for e in lcm.EventLog(str(tmp_path / "out.lcmlog"), "r") if e.channel == "GNSS"
    ]
    lat = np.array([f.lat_deg for f in fixes])
    assert np.all(np.abs(lat - lat[0]) < 0.01) and all(math.isfinite(f.accuracy_m) for f in fixes)
