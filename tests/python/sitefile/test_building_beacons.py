"""building.toml (parse, errors naming file/entry/field, merge into a site file) and the BLE beacon
learning of radiomap build (synthetic readings from a known log-distance model)."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest
from stridefix import ble_scan_t
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.radiomap import beacons as B
from stridefix_analyzer.radiomap.building import BuildingError, building_toml, merge_building, read_building
from stridefix_common.geodesy import project

EXAMPLE = pathlib.Path(__file__).resolve().parents[3] / "docs" / "examples" / "building.toml"


def test_example_parses_with_its_counts():
    b = read_building(EXAMPLE)
    # outline 4 + room 1 + room 1 + floor-1 outline 4 segments
    assert len(b.walls) == 10 and len(b.ports) == 2 and len(b.beacons) == 3
    assert b.ports[1][0] == 2 and (b.ports[1][4], b.ports[1][5]) == (0, 1)  # stairs joining 0..1
    assert b.walls[3] == (0.0, 8.0, 0.0, 0.0, 0)  # closed: the last point joins the first
    # the geo-located beacon: projected about [geo] (rotation 0: map frame = east-north)
    e, n = project([49.46125], [11.11115], 49.4612, 11.1110)
    ident, x, y, floor, rssi = b.beacons[2]
    assert ident == 0xBEAC20230003 and floor == 1 and math.isnan(rssi)
    assert (x, y) == pytest.approx((e[0], n[0]), abs=1e-9)
    assert 10.0 < x < 12.0 and 5.0 < y < 6.0  # 0.00015° lon ≈ 10.9 m, 0.00005° lat ≈ 5.6 m


def test_rotation_turns_the_projected_position(tmp_path):
    text = EXAMPLE.read_text().replace("rotation_deg = 0.0", "rotation_deg = 90.0")
    (tmp_path / "b.toml").write_text(text)
    x0, y0 = read_building(EXAMPLE).beacons[2][1:3]
    x, y = read_building(tmp_path / "b.toml").beacons[2][1:3]
    # map axes turned 90° CCW: east becomes -y, north becomes +x
    assert (x, y) == pytest.approx((y0, -x0), abs=1e-9)


def test_merge_and_round_trip(tmp_path):
    site = sitefile.new_site(floor_height_m=[0.0, 3.5])
    counts = merge_building(site, read_building(EXAMPLE), "building.toml")
    assert counts == {"walls": 10, "ports": 2, "beacons": 3}
    path = tmp_path / "s.sfsite"
    sitefile.write_site(path, site)
    back = sitefile.read_site(path)
    assert back.has_geo and back.origin_alt_m == 346.0 and back.n_walls == 10 and back.n_ports == 2
    assert list(back.beacon_id) == sorted(back.beacon_id)
    assert back.beacon_rssi_1m_dbm[0] == -61.0 and math.isnan(back.beacon_rssi_1m_dbm[1])
    assert (back.ble_rssi_1m_dbm, back.ble_path_loss_exponent, back.ble_range_sigma_db) == (-59.0, 2.0, 6.0)


def test_writer_output_reads_back_the_same(tmp_path):
    b = read_building(EXAMPLE)
    (tmp_path / "w.toml").write_text(building_toml(b))
    again = read_building(tmp_path / "w.toml")
    assert again.walls == b.walls and again.ports == b.ports and again.geo == b.geo
    assert [r[:4] for r in again.beacons] == [r[:4] for r in b.beacons]


@pytest.mark.parametrize(
    "old,new,message",
    [
        ('kind = "stairs"', 'kind = "ramp"', "[[port]] 2: kind: 'ramp' is not one of door, stairs, elevator"),
        ("radius_m = 1.5", "radius_m = 0.0", "[[port]] 2: radius_m: 0 must be > 0"),
        ("floors = [0]", "floors = [0, 1]", "[[port]] 1: floors: a door joins one floor, got [0, 1]"),
        (
            'id = "BE:AC:20:23:00:02"',
            'id = "BE:AC:20:23:00:01"',
            "[[beacon]] 2: id: BE:AC:20:23:00:01 already given",
        ),
        ('id = "BE:AC:20:23:00:02"', 'id = "beacon-2"', "[[beacon]] 2: id: 'beacon-2' is not a MAC"),
        ("points = [[0.0, 4.0], [8.0, 4.0]]", "points = [[0.0, 4.0]]", "[[wall]] 2: points: needs a list"),
        (
            "points = [[0.0, 4.0], [8.0, 4.0]]",
            "points = [[0.0, 4.0], [0.0, 4.0]]",
            "[[wall]] 2: points[0]: zero-length",
        ),
        (
            "path_loss_exponent = 2.0",
            "path_loss_exponent = -1.0",
            "[ble]: path_loss_exponent: -1 must be > 0",
        ),
        ('format = "stridefix-building 1"', 'format = "x"', "format: 'x', expected 'stridefix-building 1'"),
        ("origin_lat_deg = 49.4612", "origin_lat_deg = 91.0", "[geo]: origin_lat_deg: 91 outside -90..90"),
    ],
)
def test_errors_name_file_entry_and_field(tmp_path, old, new, message):
    text = EXAMPLE.read_text()
    assert old in text
    path = tmp_path / "building.toml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(BuildingError) as info:
        read_building(path)
    assert str(info.value).startswith(f"{path}: {message}")


# --- beacon learning -------------------------------------------------------------------------------

A_DBM, N_EXP, SIGMA_DB = -61.0, 2.2, 2.0
BEACONS = {0xA1: (5.0, 3.0), 0xA2: (22.0, 12.0), 0xA3: (12.0, 25.0)}


class _Rec:
    """A recording stand-in: truth waypoints and BLE rows (what place_readings reads)."""

    def __init__(self, truth, ble):
        self.truth, self.ble = truth, ble


def _synthetic(seed=1, beacons=BEACONS, lawn_m=30.0):
    """A lawn-mower walk over a lawn_m square (rows 5 m apart, 1 m/s, a waypoint at each row end)
    and one reading per beacon per second from the model with σ noise (all heard: no censoring)."""
    from stridefix_analyzer.io.logread import Table

    rng = np.random.default_rng(seed)
    pts = []
    for k, y in enumerate(np.arange(0.0, lawn_m + 0.1, 5.0)):
        pts += [(0.0, y), (lawn_m, y)] if k % 2 == 0 else [(lawn_m, y), (0.0, y)]
    t = np.concatenate([[0.0], np.cumsum([math.dist(a, b) for a, b in zip(pts, pts[1:])])]) * 1e6
    wx, wy = np.array([p[0] for p in pts]), np.array([p[1] for p in pts])
    truth = Table({"t_us": t.astype(np.int64), "x_m": wx, "y_m": wy, "floor": np.zeros(len(t), np.int64)})
    rows = []
    for ts in np.arange(t[0], t[-1], 1e6):
        x, y = np.interp(ts, t, wx), np.interp(ts, t, wy)
        for b, (bx, by) in beacons.items():
            d = max(math.hypot(x - bx, y - by), 1.0)
            rows.append((int(ts), b, A_DBM - 10 * N_EXP * math.log10(d) + rng.normal(0, SIGMA_DB)))
    a = list(zip(*rows))
    ble = Table(
        {
            "t_us": np.asarray(a[0], np.int64),
            "beacon_id": np.asarray(a[1], np.int64),
            "rssi_dbm": np.asarray(a[2], float),
        }
    )
    return _Rec(truth, ble)


def test_learn_recovers_positions_and_model():
    placed = B.place_readings([_synthetic()])
    r = B.learn_beacons(placed)
    assert sorted(r["beacons"]) == sorted(BEACONS)
    for b, (bx, by) in BEACONS.items():
        x, y = r["beacons"][b][:2]
        assert math.hypot(x - bx, y - by) < 1.5, (b, x, y)
    assert r["path_loss_exponent"] == pytest.approx(N_EXP, abs=0.25)
    assert r["rssi_1m_dbm"] == pytest.approx(A_DBM, abs=2.0)
    assert r["range_sigma_db"] == pytest.approx(SIGMA_DB, abs=0.4)


def test_fit_model_on_known_positions():
    placed = B.place_readings([_synthetic(seed=2)])
    m = B.fit_model(placed, {b: (x, y, 0) for b, (x, y) in BEACONS.items()})
    assert m["learnt"]
    assert m["path_loss_exponent"] == pytest.approx(N_EXP, abs=0.15)
    assert m["rssi_1m_dbm"] == pytest.approx(A_DBM, abs=1.0)
    assert m["range_sigma_db"] == pytest.approx(SIGMA_DB, abs=0.3)


def test_mac_check_finds_a_swapped_table():
    placed = B.place_readings([_synthetic(seed=3)])
    # the table names the beacons the other way round: the check follows the RSSI, not the names
    table = {"B1": (*BEACONS[0xA2], 0), "B2": (*BEACONS[0xA1], 0)}
    r = B.site_beacons([_synthetic(seed=3)], table)
    assert r["report"]["table_matched"] == {"B1": f"{0xA2:012x}", "B2": f"{0xA1:012x}"}
    assert r["report"]["from_table"] == 2 and r["report"]["learnt"] == 1
    assert B.mac_check(placed, table)["B1"]["loudest"] == 0xA2


def test_sparse_beacon_left_out():
    rec = _synthetic(seed=4)
    keep = (rec.ble["beacon_id"] != 0xA3) | (np.arange(len(rec.ble)) % 20 == 0)
    rec.ble = rec.ble.rows(np.flatnonzero(keep))
    r = B.learn_beacons(B.place_readings([rec]))
    assert 0xA3 not in r["beacons"] and 0xA3 in r["left_out"]


def test_ble_scan_type_is_the_importers():
    assert ble_scan_t().n == 0
