"""The data-set protocol: a new data set is one module plus its test.

GIVEN a tiny handmade format (``*.tiny`` text files, defined below as one Dataset subclass and
registered, nothing else edited), THEN the registry lists it, ``stridefix import tinywalk`` writes its
raw-sensor LCM log, and realbench finds its walks (``--format tinywalk``) and prepares them through
the real firmware. Also: the built-in sets' registry entries and side files (floor plan, beacons).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import lcm
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer import datasets
from stridefix_analyzer.cli import main as stridefix_main
from stridefix_analyzer.datasets.protocol import (
    Dataset,
    DatasetReadError,
    UnknownDatasetError,
    WalkDiscoveryError,
    WalkGroup,
)
from stridefix_analyzer.datasets.rawwalk import RawWalk, finite, wifi_table
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import Table, read_logs
from stridefix_lab.cli import build_parser
from stridefix_lab.realbench import walks as rb_walks
from stridefix_lab.realbench.prepare import PrepareJob, prepare

from .conftest import GSD, MSINDOOR

# --- the whole "data set module" of the tiny format ------------------------------------------------


class TinyWalk(Dataset):
    """``imu,t_ms,ax,ay,az,gx,gy,gz`` / ``wifi,t_ms,bssid_hex,rssi_dbm`` / ``pos,t_ms,x,y,floor``."""

    name = "tinywalk"
    title = "handmade test walks (*.tiny)"
    description = "Import tiny handmade walks."
    input_metavar = "WALK.tiny"
    input_noun = "walk"
    summary_keys = ("trace", "out", "messages", "skipped_lines", "duration_s", "waypoints")

    def find_walks(self, dirs):
        groups = []
        for d in map(Path, dirs):
            files = sorted(d.glob("*.tiny"))
            if not files:
                raise WalkDiscoveryError(f"{d}: no *.tiny walks")
            groups.append(WalkGroup(d.name, tuple(files), d))
        return groups

    def read(self, path, *, max_wifi_age_s=None, **options):
        try:
            lines = Path(path).read_text(encoding="utf-8").splitlines()
        except OSError as exc:
            raise DatasetReadError(path, f"cannot read ({exc.strerror})") from None
        imu, scans, pos, skipped = [], {}, [], []
        for n, line in enumerate(lines, 1):
            kind, *f = line.split(",")
            try:
                if kind == "imu":
                    imu.append([int(f[0]) * 1000, *finite(f[1:7])])
                elif kind == "wifi":
                    scans.setdefault(int(f[0]) * 1000, []).append(
                        (int(f[1], 16), float(f[2]), 2412, math.nan)
                    )
                elif kind == "pos":
                    pos.append((int(f[0]) * 1000, float(f[1]), float(f[2]), int(f[3])))
                else:
                    skipped.append((n, f"unknown record {kind!r}"))
            except (ValueError, IndexError) as exc:
                skipped.append((n, str(exc)))
        a = np.asarray(imu, float).reshape(-1, 7)
        p = np.asarray(pos, float).reshape(-1, 4)
        return RawWalk(
            path=str(path),
            imu=Table({"t_us": a[:, 0].astype(np.int64), "accel_mps2": a[:, 1:4], "gyro_radps": a[:, 4:7]}),
            wifi=wifi_table(sorted(scans.items())),
            truth=Table(
                {
                    "t_us": p[:, 0].astype(np.int64),
                    "x_m": p[:, 1],
                    "y_m": p[:, 2],
                    "floor": p[:, 3].astype(np.int64),
                }
            ),
            skipped=skipped,
        )

    def summary(self, raw):
        span = raw.time_span_us() or (0, 0)
        return {
            "trace": raw.path,
            "messages": {"IMU": len(raw.imu), "WIFI": raw.n_scans, "TRUTH": len(raw.truth)},
            "skipped_lines": len(raw.skipped),
            "duration_s": (span[1] - span[0]) / 1e6,
            "waypoints": len(raw.truth),
        }

    def format_summary(self, s):
        return f"{Path(s['trace']).name}: {s['messages']['IMU']} IMU samples"


# --- fixtures ------------------------------------------------------------------------------------


def tiny_lines(seconds: int = 20) -> list[str]:
    """A phone at rest for ``seconds`` s (50 Hz), a scan of 3 APs every second, a waypoint every 5 s
    walking east along y = 2 m, and one bad line."""
    out = [f"imu,{1000 + 20 * i},0.0,0.0,9.81,0.0,0.0,0.0" for i in range(seconds * 50)]
    for s in range(1, seconds):
        out += [f"wifi,{1000 + 1000 * s},{0xA0 + ap:012x},{-50 - 10 * ap - s % 3}" for ap in range(3)]
    out += [f"pos,{1000 + 5000 * k},{2.0 * k},2.0,0" for k in range(seconds // 5)]
    return out + ["garbage"]


@pytest.fixture
def tiny():
    """GIVEN the tiny format registered (and removed again afterwards)."""
    ds = datasets.register(TinyWalk())
    yield ds
    datasets.unregister(ds.name)


@pytest.fixture
def tiny_dir(tmp_path) -> Path:
    """GIVEN two tiny walks in a folder."""
    d = tmp_path / "tinyfloor"
    d.mkdir()
    for name, n in (("a", 20), ("b", 15)):
        (d / f"{name}.tiny").write_text("\n".join(tiny_lines(n)) + "\n", encoding="utf-8")
    return d


# --- registry ------------------------------------------------------------------------------------


def test_builtin_sets_are_found_without_a_list():
    assert datasets.names()[:2] == ("msindoor", "gsd")
    for name in ("msindoor", "gsd"):
        ds = datasets.get(name)
        assert ds.name == name and ds.defaults.max_wifi_age_s == 2.0
    with pytest.raises(UnknownDatasetError, match="unknown format 'nope'; known: msindoor, gsd"):
        datasets.get("nope")


def test_a_registered_set_is_listed_and_its_name_guarded(tiny):
    assert "tinywalk" in datasets.names() and datasets.get("tinywalk") is tiny
    with pytest.raises(ValueError, match="already registered"):
        datasets.register(TinyWalk())
    datasets.unregister("tinywalk")
    assert "tinywalk" not in datasets.names()
    datasets.register(tiny)


# --- stridefix import ----------------------------------------------------------------------------


def test_stridefix_import_writes_the_new_sets_log(tiny, tiny_dir, tmp_path, capsys):
    out = tmp_path / "a.lcmlog"
    assert stridefix_main(["import", "tinywalk", str(tiny_dir / "a.tiny"), "-o", str(out)]) == 0
    io = capsys.readouterr()
    line = json.loads(io.out.splitlines()[0])
    assert line["messages"] == {"IMU": 1000, "WIFI": 19, "TRUTH": 4} and line["skipped_lines"] == 1
    assert "a.tiny: 1000 IMU samples" in io.err and "1/1 walk(s) imported" in io.err
    data = read_logs([out])
    assert len(data.table("IMU")) == 1000 and data.table("IMU")["seq"].tolist()[:3] == [0, 1, 2]
    wifi = data.table("WIFI")
    assert wifi["n_ap"].tolist() == [3] * 19 and wifi["scan_id"].tolist() == list(range(19))
    assert_allclose(data.table("TRUTH")["x_m"], [0.0, 2.0, 4.0, 6.0])
    stamps = [e.timestamp for e in lcm.EventLog(str(out), "r")]
    assert stamps == sorted(stamps) and len(stamps) == 1000 + 19 + 4


def test_stridefix_import_names_a_missing_walk(tiny, tmp_path, capsys):
    rc = stridefix_main(["import", "tinywalk", str(tmp_path / "gone.tiny"), "--out", str(tmp_path)])
    assert rc == 2 and "gone.tiny: cannot read" in capsys.readouterr().err


# --- realbench -----------------------------------------------------------------------------------


def test_realbench_finds_and_prepares_the_new_sets_walks(tiny, tiny_dir, tmp_path, stridefixd):
    args = build_parser().parse_args(
        ["realbench", "fusion", "--format", "tinywalk", str(tiny_dir), "--out", "r.json"]
    )
    assert args.format == "tinywalk"
    (group,) = rb_walks.find_groups(rb_walks.dataset("tinywalk"), [tiny_dir])
    assert group.label == "tinyfloor" and [p.name for p in group.walks] == ["a.tiny", "b.tiny"]
    walk = prepare(
        PrepareJob(
            trace=group.walks[0],
            dataset=tiny,
            work_dir=tmp_path / "work",
            cache_dir=tmp_path / "cache",
            firmware=Firmware(stridefixd),
            read_options={"max_wifi_age_s": 2.0},
            reimport=False,
            cell_size_m=2.0,
            param_sets=[],
            heading_candidates={"learned": []},
        )
    )
    assert walk["error"] is None, walk["error"]
    assert walk["floors"] == [0] and walk["first_waypoint"] == (1_000_000, 0.0, 2.0, 0)
    assert len(walk["waypoint_t_us"]) == 4 and walk["import"]["cache_key"]["dataset"] == "tinywalk"
    with pytest.raises(rb_walks.RealbenchError, match="no \\*.tiny walks"):
        rb_walks.find_groups(tiny, [tmp_path / "cache"])


# --- the built-in sets' side files ---------------------------------------------------------------


def test_side_files_of_the_builtin_sets():
    if not (GSD / "BLE_Locations.csv").is_file() or not (MSINDOOR / "site1" / "F2").is_dir():
        pytest.skip("real data not found (needs ../shared/data beside the repository)")
    ble = datasets.get("gsd").beacons(GSD)
    assert ble is not None and len(ble) == 6 and ble["id"][0] == "BLE1" and ble["floor"][2] == -2
    assert datasets.get("gsd").floor_plan(GSD) is None
    plan = datasets.get("msindoor").floor_plan(MSINDOOR / "site1" / "F2")
    assert plan is not None and plan.width_m == pytest.approx(239.8175, abs=1e-3)
    assert plan.image is not None and plan.geojson["type"] == "FeatureCollection"
    assert datasets.get("msindoor").beacons(MSINDOOR / "site1" / "F2") is None


def test_phone_data_sets_switch_the_second_hard_iron_fit_off():
    # both record Android's TYPE_MAGNETIC_FIELD, already hard-iron calibrated by the phone's OS
    from stridefix_analyzer import datasets as registry

    for name in ("msindoor", "gsd"):
        assert "magcal.enable=0" in registry.get(name).firmware_sets
