"""Fixtures for the real-data tests: handmade msindoor traces, the shared msindoor data, stridefixd."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

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
        pytest.skip(f"real msindoor data not found at {REAL_TRACE} (needs ../shared/data beside "
                    "the repository)")
    return REAL_TRACE


@pytest.fixture(scope="session")
def stridefixd() -> Path:
    """The firmware binary built by CMake (make test passes its path in STRIDEFIXD)."""
    path = Path(os.environ.get("STRIDEFIXD", REPO / "build" / "firmware" / "stridefixd"))
    if not path.is_file():
        pytest.fail(f"stridefixd not built at {path}: run `make build` first")
    return path


def run_cli(*args: str, **kwargs) -> subprocess.CompletedProcess:
    """Runs the `stridefix` console script of this venv."""
    exe = Path(sys.executable).with_name("stridefix")
    return subprocess.run([str(exe), *args], capture_output=True, text=True, **kwargs)


@pytest.fixture(scope="session")
def cli():
    """The `stridefix` console script, as a function of its arguments."""
    return run_cli


@pytest.fixture(scope="session")
def realbench_small(request, tmp_path_factory, cli) -> dict:
    """GIVEN `stridefix realbench pdr-distance --limit 4` run on site1/F2: its output and JSON."""
    floor = MSINDOOR / "site1" / "F2"
    if not floor.is_dir():
        pytest.skip(f"real msindoor data not found at {floor} (needs ../shared/data beside the "
                    "repository)")
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("realbench")
    proc = cli("realbench", "pdr-distance", "--floor", str(floor), "--limit", "4",
               "--stridefixd", str(stridefixd), "--out", str(out))
    return {"proc": proc, "out": out, "floor": floor}
