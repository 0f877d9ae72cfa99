"""realbench fold sites carry the building content of the training walks (realbench/sitecontent.py):
walls opened at the training walks' crossings, the geo-reference, beacons and the path-loss model;
and the --no-floor-plan / --no-beacons / --no-gnss switches."""

from __future__ import annotations

import math
import subprocess

import lcm
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import truth_t, wifi_scan_t
from stridefix_analyzer import datasets
from stridefix_analyzer.io.sitefile import read_site
from stridefix_analyzer.radiomap import build as rm
from stridefix_analyzer.radiomap import floorplan as fp
from stridefix_analyzer.radiomap.beacons import MIN_RANGE_M
from stridefix_lab.cli import build_parser
from stridefix_lab.realbench import fold as rfold
from stridefix_lab.realbench import sitecontent as sc
from stridefix_lab.realbench.walks import RealbenchError

BEACON = 0xBEAC20230001
ONLY_HELD = 0xBEAC20230002  # heard by walk 0 only
A_DBM, N_EXP, SIGMA_DB = -60.0, 2.0, 2.0
BEACON_XY = (20.0, 15.0)


def _walk(path, seed):
    """WIFI + TRUTH of a lawn-mower walk over 40 x 30 m (8 waypoints, a scan every 2 s); walk 0's
    rows are 3 m north of the others'."""
    rng = np.random.default_rng(seed)
    xs = np.array([2, 38, 38, 2, 2, 38, 38, 2], float) + seed
    ys = np.array([2, 2, 10, 10, 18, 18, 26, 26], float) + (3.0 if seed == 0 else 0.0)
    log = lcm.EventLog(str(path), "w", overwrite=True)
    events = []
    for k, (x, y) in enumerate(zip(xs, ys)):
        m = truth_t()
        m.t_us, m.x_m, m.y_m, m.floor = int(k * 10e6), float(x), float(y), 0
        m.heading_rad, m.step_count, m.source = math.nan, -1, truth_t.SOURCE_WAYPOINT
        events.append((m.t_us, "TRUTH", m))
    for t in np.arange(1.0, 70.0, 2.0):
        m = wifi_scan_t()
        m.t_us, m.scan_id, m.complete = int(t * 1e6), 0, True
        m.bssid = [0x100 + a for a in range(5)]
        m.rssi_dbm = [float(rng.integers(-90, -40)) for _ in range(5)]
        m.n_ap, m.freq_mhz = 5, [2412] * 5
        events.append((m.t_us, "WIFI", m))
    for t_us, ch, m in sorted(events, key=lambda e: e[0]):
        log.write_event(t_us, ch, m.encode())
    log.close()
    return (np.column_stack([xs, ys]), rm.load_recordings([str(path)])[0])


def _placed(xy, seed, extra=False):
    """BLE readings along a walk's waypoint polyline of the log-distance model (A, n, sigma)."""
    rng = np.random.default_rng(100 + seed)
    pts = np.concatenate([np.linspace(a, b, 12, endpoint=False) for a, b in zip(xy[:-1], xy[1:])])
    d = np.maximum(np.hypot(pts[:, 0] - BEACON_XY[0], pts[:, 1] - BEACON_XY[1]), MIN_RANGE_M)
    rssi = A_DBM - 10 * N_EXP * np.log10(d) + SIGMA_DB * rng.standard_normal(len(pts))
    ids = np.full(len(pts), BEACON)
    if extra:  # a second beacon at (5, 25), heard by this walk only
        d2 = np.maximum(np.hypot(pts[:, 0] - 5.0, pts[:, 1] - 25.0), MIN_RANGE_M)
        pts = np.concatenate([pts, pts])
        ids = np.concatenate([ids, np.full(len(d2), ONLY_HELD)])
        rssi = np.concatenate([rssi, A_DBM - 20 * np.log10(d2) + SIGMA_DB * rng.standard_normal(len(d2))])
    return {
        "beacon_id": ids.astype(np.int64),
        "x_m": pts[:, 0],
        "y_m": pts[:, 1],
        "floor": np.zeros(len(pts), np.int64),
        "rssi_dbm": rssi,
        "n_total": np.asarray(len(pts)),
    }


class _NoFirmware:
    """Stands in for stridefixd: fails every replay (the fold stops after writing its site)."""

    def run(self, **kw):
        return subprocess.CompletedProcess(["stridefixd"], 1, "", "stub")


@pytest.fixture
def content(tmp_path):
    """GIVEN three synthetic walks (WIFI, TRUTH, BLE), a wall x = 20 (y 0..30) every walk crosses at
    its own y, and the group's content built from them."""
    walks = [_walk(tmp_path / f"w{i}.lcmlog", i) for i in range(3)]
    wall = np.array([[20.0, 0.0, 20.0, 30.0]])
    survey = fp.DoorSurvey.of(wall, [w[0] for w in walks])
    geo = {
        "has_geo": True,
        "origin_lat_deg": 49.46,
        "origin_lon_deg": 11.11,
        "origin_alt_m": 0.0,
        "geo_rotation_deg": 0.0,
    }
    placed = [_placed(w[0], i, extra=i == 0) for i, w in enumerate(walks)]
    return walks, sc.GroupContent(survey, 0, geo, None, placed, {})


def test_fold_site_carries_walls_geo_and_beacons_of_the_training_walks(content, tmp_path):
    walks, gc = content
    stats = [rm.WalkStats.from_recordings([w[1]]) for w in walks]
    total = rm.WalkStats.total(stats)
    job = rfold.FoldJob(
        index=0, walk="w0", group="g", dir=tmp_path / "w0", import_log="unused.lcmlog", firmware=_NoFirmware(),  # type: ignore[arg-type]
        K=0.45, rotation_deg=0.0, rotation_learned=False, floor_heights_m=[0.0],
        floor_heights_source="test", lowest_floor=0, min_count=1, true_start=False, param_sets=[],
        variants={}, extra={}, first_waypoint=(0, 0.0, 0.0, 0), total=total, held=stats[0],
        content=gc, content_index=0,
    )  # fmt: skip
    # WHEN the fold of walk 0 runs
    out = rfold.run_fold(job)
    site = read_site(tmp_path / "w0" / "site.sfsite")
    # THEN its site has the wall cut at walks 1 and 2's crossings (y = 2, 10, 18, 26; doors of 2 m)
    # but not at walk 0's own (y = 5, 13, 21, 29)
    assert out["fold"]["n_walls"] == site.n_walls == 5 and set(site.wall_floor) == {0}
    walls = np.column_stack([site.wall_x0_m, site.wall_y0_m, site.wall_x1_m, site.wall_y1_m])

    def crossed(walls, ys):
        return len(fp.crossings(walls, [[19.0, y, 21.0, y] for y in ys])[0])

    assert crossed(walls, [1.1, 2.0, 2.9, 9.1, 10.0, 25.1, 26.9]) == 0
    assert crossed(walls, [5.0, 13.0, 21.0, 29.0]) == 4
    w1, _ = gc.fold_fields(1)
    walls1 = np.column_stack([w1["wall_x0_m"], w1["wall_y0_m"], w1["wall_x1_m"], w1["wall_y1_m"]])
    assert crossed(walls1, [2.0, 5.0, 13.0, 21.0, 29.0]) == 0  # walk 1's fold: walk 0's doors open
    assert site.has_geo and (site.origin_lat_deg, site.origin_lon_deg) == (49.46, 11.11)
    # the beacon learnt from walks 1 and 2 within 1.5 m, the model near (A, n); the beacon only walk
    # 0 heard is not in its own fold's site
    assert list(site.beacon_id) == [BEACON]
    assert math.hypot(site.beacon_x_m[0] - BEACON_XY[0], site.beacon_y_m[0] - BEACON_XY[1]) < 1.5
    assert abs(site.ble_path_loss_exponent - N_EXP) < 0.4 and abs(site.ble_rssi_1m_dbm - A_DBM) < 3.0
    assert out["fold"]["content_content_s"] < 1.0
    # and walk 1's fold knows the beacon walk 0 heard
    fields, rec = gc.fold_fields(1)
    assert ONLY_HELD in fields["beacon_id"] and rec["beacons"] == 2


def test_content_off_leaves_the_site_as_before(content):
    walks, gc = content
    off = sc.GroupContent(None, 0, None, None, [], {})
    fields, rec = off.fold_fields(0)
    assert fields == {} and set(rec) == {"content_s"}
    on, _ = gc.fold_fields(0)
    assert {"wall_x0_m", "has_geo", "beacon_id", "ble_path_loss_exponent"} <= set(on)


def _walk_dict(xy, origin, placed):
    return {
        "waypoint_xy_m": xy,
        "waypoint_floor": np.zeros(len(xy), np.int64),
        "import": {"origin": {"lat_deg": origin[0], "lon_deg": origin[1]}},
        "ble_placed": placed,
    }


def test_group_content_of_gsd_uses_the_importer_origin_and_the_beacon_table(tmp_path):
    # GIVEN a gsd folder with a beacon table and walks read about one origin
    origin = (49.4613, 11.1110)
    (tmp_path / "BLE_Locations.csv").write_text(
        'bleID,Lat,Lon,floor\n"BLE1",49.4614,11.1111,00\n', encoding="utf-8"
    )
    xy = np.array([[0.0, 0.0], [10.0, 0.0]])
    walks = [_walk_dict(xy, origin, _placed(xy, i)) for i in range(2)]
    gsd = datasets.get("gsd")
    # WHEN the group's content is made with every part, and with each switched off
    full = sc.group_content(gsd, tmp_path, None, walks, sc.ContentOptions())
    no_gnss = sc.group_content(gsd, tmp_path, None, walks, sc.ContentOptions(gnss=False))
    no_ble = sc.group_content(gsd, tmp_path, None, walks, sc.ContentOptions(beacons=False))
    # THEN the geo-reference is the importer's origin; the table is projected about it (BLE1 is
    # 0.0001 deg north and east: 11.1 m north, 7.2 m east at 49.46 deg)
    assert full.geo is not None and (full.geo["origin_lat_deg"], full.geo["origin_lon_deg"]) == origin
    assert full.table is not None
    assert_allclose(full.table["BLE1"][:2], [7.24, 11.12], atol=0.02)
    assert full.survey is None and len(full.placed) == 2
    assert no_gnss.geo is None and no_gnss.table == full.table  # the table needs the frame, not GNSS
    assert no_ble.placed == [] and no_ble.table is None and no_ble.geo == full.geo
    # walks read about different origins share no frame: no geo-reference
    mixed = [walks[0], _walk_dict(xy, (49.0, 11.0), walks[1]["ble_placed"])]
    assert sc.group_content(gsd, tmp_path, None, mixed, sc.ContentOptions()).geo is None


@pytest.mark.parametrize(
    ("flags", "expected"),
    [
        ([], sc.ContentOptions(True, True, True)),
        (["--no-floor-plan"], sc.ContentOptions(False, True, True)),
        (["--no-beacons", "--no-gnss"], sc.ContentOptions(True, False, False)),
        (["--learn-beacons"], sc.ContentOptions(True, True, True, learn_beacons=True)),
    ],
)
def test_realbench_switches(flags, expected, monkeypatch):
    seen = {}

    def fake_run_fusion(cfg):
        seen["content"] = cfg.content
        raise RealbenchError("stop here")

    monkeypatch.setattr("stridefix_lab.realbench.cli.run_fusion", fake_run_fusion)
    args = build_parser().parse_args(
        ["realbench", "fusion", "--format", "gsd", "x", "--out", "r.json", *flags]
    )
    assert args._bench(args) == 2
    assert seen["content"] == expected


def test_real_fold_sites_carry_walls_geo_and_beacons(realbench_fusion_small):
    r = realbench_fusion_small
    assert r["proc"].returncode == 0, r["proc"].stderr[-2000:]
    (g,) = r["doc"]["groups"]
    info = g["site_content"]
    # the GeoJSON holds the walks (measured 100 %) and the geo-reference comes from it
    assert info["floor_plan"]["waypoints_inside_outline"] == 1.0 and info["floor_plan"]["floor"] == 1
    assert info["geo"]["source"] == "floor plan GeoJSON"
    plan = fp.load_plan(str(r["floor"] / "geojson_map.json"))
    for row in g["walk_rows"]:
        site = read_site(f"{row['dir']}/site.sfsite")
        assert 300 < site.n_walls < 3000 and set(site.wall_floor) == {1}
        assert (
            site.has_geo
            and site.origin_lat_deg == plan.lat_min_deg
            and site.origin_lon_deg == plan.lon_min_deg
        )
        # msindoor has no beacon table: beacons placed from walks alone are left out by default
        assert site.n_beacons == 0
        assert row["fold"]["content_content_s"] < 1.0
    assert info["beacons"] == sc.LEARNT_ONLY_NOTE
