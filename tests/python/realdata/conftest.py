"""Fixtures for the real-data tests: handmade msindoor traces, the shared msindoor data, stridefixd."""

from __future__ import annotations

from pathlib import Path

import pytest
from stridefix_analyzer.io.results import read_realbench_results

REPO = Path(__file__).resolve().parents[3]
MSINDOOR = REPO.parent / "shared" / "data" / "msindoor"
REAL_TRACE = MSINDOOR / "site1" / "F2" / "path_data_files" / "5dda0405c5b77e0006b17428.txt"

# A small trace with known content (tab-separated; line numbers matter: see the tests).
#  line 1-2: header (FloorName B1)
#  accel at 1000, 1020, 1040 ms; gyro at 1000 (x=0), 1030 (x=0.3), 1050 (x=0.5) -> at 1020: x=0.2
#  mag at 1000, 1040; scan at 5000 (one cached entry, age 3.5 s) and 8000 (one BSSID twice)
#  malformed: line 9 (wrong field count), 10 (not a number), 11 (two records run together),
#             12 (no time)
#  waypoints at the end of the file, out of time order, like the real files
HANDMADE_LINES = [
    "#\tstartTime:1000",
    "#\tSiteID:site-x\tSiteName:Test\tFloorId:fl-1\tFloorName:B1",
    "1000\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3",
    "1000\tTYPE_GYROSCOPE\t0.0\t-0.1\t0.0\t3",
    "1000\tTYPE_MAGNETIC_FIELD\t10.0\t20.0\t-30.0\t3",
    "1000\tTYPE_ACCELEROMETER_UNCALIBRATED\t9\t9\t9\t0\t0\t0\t3",
    "1020\tTYPE_ACCELEROMETER\t0.3\t0.4\t9.6\t3",
    "1030\tTYPE_GYROSCOPE\t0.3\t-0.1\t0.0\t3",
    "1035\tTYPE_ACCELEROMETER\t0.5\t0.6",
    "1036\tTYPE_GYROSCOPE\tabc\t0.0\t0.0\t3",
    "1037\tTYPE_WIFI\tnet\taa:bb:cc:dd:ee:01\t-50\t2412\t10371037\tTYPE_ACCELEROMETER\t1\t2\t3\t3",
    "oops\tTYPE_ACCELEROMETER\t1\t2\t3\t3",
    "1040\tTYPE_ACCELEROMETER\t0.5\t0.6\t9.4\t3",
    "1040\tTYPE_MAGNETIC_FIELD\t11.0\t21.0\t-31.0\t3",
    "1050\tTYPE_GYROSCOPE\t0.5\t-0.1\t0.0\t3",
    "5000\tTYPE_WIFI\tnet-a\taa:bb:cc:dd:ee:01\t-50\t2412\t4900",
    "5000\tTYPE_WIFI\tnet-b\taa:bb:cc:dd:ee:02\t-70\t5180\t1500",
    "5000\tTYPE_WIFI\t\t0a:0b:0c:0d:0e:0f\t-61\t2437\t4990",
    "8000\tTYPE_WIFI\tnet-a\taa:bb:cc:dd:ee:01\t-55\t2412\t7000",
    "8000\tTYPE_WIFI\tnet-a\taa:bb:cc:dd:ee:01\t-52\t2412\t7900",
    "9000\tTYPE_WAYPOINT\t4.0\t6.0",
    "1000\tTYPE_WAYPOINT\t1.0\t2.0",
    "#\tendTime:9000",
]


@pytest.fixture
def handmade_trace(tmp_path) -> Path:
    """GIVEN a handmade trace file (HANDMADE_LINES) in tmp_path."""
    path = tmp_path / "handmade.txt"
    path.write_text("\n".join(HANDMADE_LINES) + "\n", encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def real_trace() -> Path:
    """One real site1/F2 trace from ../shared/data/msindoor (skips when the data is absent)."""
    if not REAL_TRACE.is_file():
        pytest.skip(
            f"real msindoor data not found at {REAL_TRACE} (needs ../shared/data beside the repository)"
        )
    return REAL_TRACE


@pytest.fixture(scope="session")
def realbench_small(request, tmp_path_factory, cli, lab) -> dict:
    """GIVEN `stridefix-lab realbench pdr-distance --limit 4` run on site1/F2: its output and JSON."""
    floor = MSINDOOR / "site1" / "F2"
    if not floor.is_dir():
        pytest.skip(f"real msindoor data not found at {floor} (needs ../shared/data beside the repository)")
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("realbench")
    proc = lab(
        "realbench",
        "pdr-distance",
        "--floor",
        str(floor),
        "--limit",
        "4",
        "--stridefixd",
        str(stridefixd),
        "--out",
        str(out),
    )
    return {"proc": proc, "out": out, "floor": floor}


# --- GetSensorData (gsd) logfiles ------------------------------------------------------------------

GSD = REPO.parent / "shared" / "data" / "gsd"
REAL_GSD = GSD / "IPIN2023_T3_TrainingTrial01_repetition01.txt"

# A small GetSensorData excerpt with known content (';'-separated; line numbers matter: see the tests).
#  inertial clock: AppTimestamp = SensorTimestamp - 4998.999 s (+ latency): the first ACCE and GYRO
#    arrive 14-15 ms late, every other one 0 ms, so the start-of-file median offset is -4998.999 s and
#    ACCE 5000.000/.020/.040 -> 1.001/1.021/1.041 s (not 1.015, its AppTimestamp)
#  gyro x: 0 at 1.001 s, 0.3 at 1.031 s, 0.5 at 1.051 s -> 0, 0.2, 0.4 at the accel times
#  MAGN 5000.010/.030 -> 1.011/1.031 s; PRES 1013.25 and 1000.00 mbar at 1.1 and 1.3 s
#  GNSS: a fix at 1.5 s logged twice (the repeat dropped), another at 2.5 s
#  WIFI: scan at 2.000 s (records at 2.000, 2.000, 2.004 s; the third last seen at 4998.499 - 4998.999
#        = -0.5 s, 2.5 s before the scan: cached, dropped); scan at 6.000 s (20:23:..:01 twice, the
#        fresher -62 dBm kept; an SSID holding ';' and a trailing ';')
#  malformed: line 10 (5 fields), 14 (not a number), 26 (no record tag)
#  POSI: 3 s at the origin 49.46/11.11 (floor 0), then out of time order 9 s (+0.0001 deg in both,
#        floor -1) and 6 s (+0.0001 deg latitude, floor 0); building id 100
GSD_LINES = [
    "% LogFile created by the 'GetSensorData' App for Android.",
    "% Model:                   \tSM-TEST",
    "% Pressure data:      \t'PRES;AppTimestamp(s);SensorTimestamp(s);Pres(mbar);Accuracy(integer)'",
    "% POSI Reference:    \t\t'POSI;Timestamp(s);Counter;Latitude(degrees); Longitude(degrees);"
    "floor ID(0,1,2..4);Building ID(0,1,2..3);'",
    "MAGN;1.012;5000.010;10.0;20.0;-30.0;0",
    "ACCE;1.015;5000.000;0.1;0.2;9.8;3",
    "GYRO;1.016;5000.000;0.0;-0.1;0.0;3",
    "AHRS;1.017;5000.000;49.9;11.5;-16.5;0.4;0.03;-0.08;3",
    "ACCE;1.021;5000.020;0.3;0.4;9.6;3",
    "ACCE;1.025;5000.025;0.7;0.8",
    "GYRO;1.031;5000.030;0.3;-0.1;0.0;3",
    "MAGN;1.032;5000.030;11.0;21.0;-31.0;0",
    "ACCE;1.041;5000.040;0.5;0.6;9.4;3",
    "GYRO;1.045;5000.045;abc;0.0;0.0;3",
    "GYRO;1.051;5000.050;0.5;-0.1;0.0;3",
    "PRES;1.100;5000.099;1013.25;3",
    "LIGH;1.150;5000.149;349.0;3",
    "PRES;1.300;5000.299;1000.00;3",
    "GNSS;1.500;1686729678.0000;49.461269;11.111049;346.000;79.500;9.0;0.1;22;19",
    "GNSS;1.510;1686729678.0000;49.461269;11.111049;346.000;79.500;9.0;0.1;22;19",
    "WIFI;2.000;5000.990;SSID_A;20:23:00:00:00:01;2437;-60",
    "WIFI;2.000;5000.980;SSID_B;20:23:00:00:00:15;5180;-71",
    "WIFI;2.004;4998.499;SSID_C;20:23:00:00:00:45;2412;-80",
    "GNSS;2.500;1686729679.0000;49.461268;11.111051;347.500;0.000;12.0;0.0;23;21",
    "POSI;3.0000;1;49.460000000000;11.110000000000;0;100",
    "this is not a record",
    "WIFI;6.000;5004.900;SSID_A;20:23:00:00:00:01;2437;-65",
    "WIFI;6.000;5004.990;SSID_A;20:23:00:00:00:01;2437;-62",
    "WIFI;6.001;5004.990;we;got;semicolons;20:23:00:00:00:82;2462;-64;",
    "POSI;9.0000;3;49.460100000000;11.110100000000;-1;100",
    "POSI;6.0000;2;49.460100000000;11.110000000000;0;100",
]


@pytest.fixture
def gsd_log(tmp_path) -> Path:
    """GIVEN a handmade GetSensorData excerpt (GSD_LINES) in tmp_path."""
    path = tmp_path / "handmade_gsd.txt"
    path.write_text("\n".join(GSD_LINES) + "\n", encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def real_gsd() -> Path:
    """One real IPIN 2023 logfile from ../shared/data/gsd (skips when the data is absent)."""
    if not REAL_GSD.is_file():
        pytest.skip(
            f"real GetSensorData logs not found at {REAL_GSD} (needs ../shared/data beside the repository)"
        )
    return REAL_GSD


@pytest.fixture(scope="session")
def realbench_fusion_small(request, tmp_path_factory, cli, lab) -> dict:
    """GIVEN `stridefix-lab realbench --format msindoor site1/F2 --limit 5 --out results.json` (the
    leave-one-walk-out fusion benchmark on 5 real walks): its process, results and folders."""
    floor = MSINDOOR / "site1" / "F2"
    if not floor.is_dir():
        pytest.skip(f"real msindoor data not found at {floor} (needs ../shared/data beside the repository)")
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("realbench_fusion")
    results = out / "results.json"
    proc = lab(
        "realbench",
        "--format",
        "msindoor",
        str(floor),
        "--limit",
        "5",
        "--stridefixd",
        str(stridefixd),
        "--out",
        str(results),
        "--quiet",
    )
    doc = read_realbench_results(results) if results.is_file() else None
    return {
        "proc": proc,
        "out": out,
        "results": results,
        "doc": doc,
        "floor": floor,
        "stridefixd": stridefixd,
    }
