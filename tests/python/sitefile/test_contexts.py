"""The context map (radiomap/contexts.py, building_contexts.py): building.toml's [[building]], port
extras and [[context]] round-trip and name file/entry/field in their errors; the builder derives the
contexts, LSDs and CDDs of building_spec.md with the constellation rules' numbers (6 dB margin,
elsewhere + 3 dB or the median, the BLE model at 5 m, 2 hits from 4 members); `radiomap build
--building` writes it and `radiomap show` prints it; a one-building site gets one by itself."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import fix_t, pose_t, site_t
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.radiomap import contexts
from stridefix_analyzer.radiomap.building import (
    Building,
    BuildingError,
    BuildingOutline,
    ContextSpec,
    PortExtra,
    building_toml,
    merge_building,
    read_building,
)

S = 1_000_000
A_OUTLINE = [(0.0, 0.0), (20.0, 0.0), (20.0, 10.0), (0.0, 10.0)]
B_OUTLINE = [(30.0, 0.0), (50.0, 0.0), (50.0, 10.0), (30.0, 10.0)]
BEACON_B = 0xBEAC00000001


def campus_building() -> Building:
    """Two buildings, A (floors 0, 1) and B (floor 0, one beacon), two outdoor doors, a staircase in
    A linked with A's door, and B's floor on the particle scheme."""
    return Building(
        ble={"rssi_1m_dbm": -59.0, "path_loss_exponent": 2.0, "range_sigma_db": 6.0},
        ports=[(1, 20.0, 5.0, 1.0, 0, 0), (1, 30.0, 5.0, 1.0, 0, 0), (2, 10.0, 8.0, 2.0, 0, 1)],
        beacons=[(BEACON_B, 40.0, 5.0, 0, math.nan)],
        buildings=[BuildingOutline("A", A_OUTLINE, [0, 1]), BuildingOutline("B", B_OUTLINE, [0])],
        port_extras=[
            PortExtra(name="A-door", building="A", outdoor=True),
            PortExtra(name="B-door", building="B", outdoor=True),
            PortExtra(
                name="A-stairs",
                building="A",
                steps=20,
                end_lo=(9.0, 8.0),
                end_hi=(11.0, 8.0),
                links=["A-door"],
            ),
        ],
        contexts=[ContextSpec("floor", "B", 0, scheme="particle")],
    )


#: RPs: A/0 at x 5 and 15, A/1 the same, B/0 at x 35 and 45, one outdoor RP at x 25 (all y 5)
RPS = [(5.0, 0), (15.0, 0), (5.0, 1), (15.0, 1), (35.0, 0), (45.0, 0), (25.0, 0)]
#: mean RSSI per AP per RP (None: not heard); see the expected constellations below
HEARD = {
    0x10: [-40, -50, -60, -62, None, None, -70],  # A/0: −40 ≥ −60 + 6; max(−57, median −45) = −45
    0x11: [-50, None, -53, None, None, None, None],  # 3 dB apart: identifies neither floor
    0x12: [-70, None, -45, -55, None, None, None],  # A/1: max(−67, −50) = −50
    0x13: [None, None, None, None, None, None, -60],  # outdoors only: no member (outdoor is GNSS)
    0x14: [None, None, None, None, -50, -60, -64],  # B/0 is a BLE floor: not its member
    0x15: [-40, -80, -50, None, None, None, None],  # A/0: max(−47, median −60) = −47
    0x16: [-45, -45, None, None, None, None, None],  # A/0, heard nowhere else: the median −45
    0x17: [None, -55, None, None, None, None, None],  # A/0: −55
}


def campus_site() -> site_t:
    aps = sorted(HEARD)
    entries = [(a, r, float(m)) for a, ap in enumerate(aps) for r, m in enumerate(HEARD[ap]) if m is not None]
    return sitefile.new_site(
        name="campus",
        floor_height_m=[0.0, 3.5],
        ap_bssid=aps,
        rp_x_m=[x for x, _ in RPS],
        rp_y_m=[5.0] * len(RPS),
        rp_floor=[f for _, f in RPS],
        rp_scans=[4] * len(RPS),
        entry_ap=[e[0] for e in entries],
        entry_rp=[e[1] for e in entries],
        entry_mean_dbm=[e[2] for e in entries],
        entry_std_db=[1.0] * len(entries),
        entry_count=[4] * len(entries),
    )


def _members(site, c):
    return {site.cdd_id[i]: site.cdd_min_dbm[i] for i in range(site.n_cdd) if site.cdd_context[i] == c}


def test_building_toml_round_trips_the_context_tables(tmp_path):
    b = campus_building()
    path = tmp_path / "campus.toml"
    path.write_text(building_toml(b))
    again = read_building(path)
    assert again.buildings == b.buildings
    assert again.port_extras == b.port_extras
    assert again.contexts == b.contexts
    assert again.ports == b.ports
    assert again.floors() == {0, 1}


def test_building_toml_without_context_tables_has_none(tmp_path):
    path = tmp_path / "plain.toml"
    path.write_text(building_toml(Building(ports=[(2, 1.0, 1.0, 1.0, 0, 1)])))
    again = read_building(path)
    assert (again.buildings, again.port_extras, again.contexts) == ([], [], [])


BASE = 'format = "stridefix-building 1"\n[[building]]\nname = "A"\noutline = [[0, 0], [9, 0], [9, 9]]\nfloors = [0, 1]\n'
PORT = '[[port]]\nkind = "stairs"\nx_m = 1.0\ny_m = 1.0\nradius_m = 1.0\nfloors = [0, 1]\n'


@pytest.mark.parametrize(
    "text,message",
    [
        (BASE + PORT, "[[port]] 1: steps: stairs need their step count (> 0) for the context map"),
        (
            BASE + PORT + 'steps = 12\nbuilding = "Z"\n',
            "[[port]] 1: building: 'Z' is not a [[building]] name",
        ),
        (BASE + PORT + 'steps = 12\nlinks = ["nope"]\n', "[[port]] 1: links: 'nope' is not a [[port]] name"),
        (BASE + PORT + "steps = 12\nends = [[1, 1]]\n", "[[port]] 1: ends: [[1, 1]] is not [[x, y] lowest"),
        (
            BASE.replace("[9, 9]]", "]"),
            "[[building]] 1: outline: needs a list of at least three [x, y] vertices",
        ),
        (BASE + BASE.split("\n", 1)[1], "[[building]] 2: name: 'A' already given"),
        (
            BASE + '[[context]]\nkind = "floor"\nbuilding = "A"\nfloor = 5\n',
            "[[context]] 1: floor: 5 is not one of",
        ),
        (
            BASE + '[[context]]\nkind = "floor"\nbuilding = "A"\nfloor = 1\nscheme = "controller"\n',
            "[[context]] 1: scheme: 'controller' is not a fusion scheme",
        ),
        (
            BASE + '[[context]]\nkind = "outdoor"\nmethod = "uwb"\n',
            "[[context]] 1: method: 'uwb' is not one of",
        ),
        (
            BASE + '[[context]]\nkind = "outdoor"\nfloor = 0\n',
            "[[context]] 1: floor: the outdoor context has no floor",
        ),
    ],
)
def test_context_table_errors_name_file_entry_field(tmp_path, text, message):
    path = tmp_path / "b.toml"
    path.write_text(text)
    with pytest.raises(BuildingError) as info:
        read_building(path)
    assert str(info.value).startswith(f"{path}: {message}")


def test_derivation_contexts_lsd_and_cdd_numbers(tmp_path):
    site = campus_site()
    b = campus_building()
    merge_building(site, b)
    report = contexts.build_context_map(site, b)
    assert list(site.building_name) == ["A", "B"]
    # contexts: outdoor (its floor: the outdoor doors' lowest), A/0, A/1, B/0
    assert list(site.context_kind) == [site_t.CONTEXT_OUTDOOR] + [site_t.CONTEXT_FLOOR] * 3
    assert list(site.context_building) == [-1, 0, 0, 1]
    assert list(site.context_floor) == [0, 0, 1, 0]
    kalman, particle = pose_t.SCHEME_KALMAN, pose_t.SCHEME_PARTICLE
    assert list(site.context_scheme) == [kalman, kalman, kalman, particle]  # B/0's [[context]] override
    wifi, ble, gnss = fix_t.METHOD_WIFI, fix_t.METHOD_BLE, fix_t.METHOD_GNSS
    assert list(site.context_method) == [gnss, wifi, wifi, ble]  # B has a beacon: BLE
    assert list(site.context_cdd_method) == list(site.context_method)
    assert _members(site, 0) == {}  # GNSS: no constellation
    assert _members(site, 1) == pytest.approx({0x10: -45.0, 0x15: -47.0, 0x16: -45.0, 0x17: -55.0})
    assert _members(site, 2) == pytest.approx({0x12: -50.0})
    assert _members(site, 3) == pytest.approx({BEACON_B: -59.0 - 20.0 * math.log10(5.0)}, abs=1e-4)
    assert list(site.context_cdd_min_hits) == [1, 2, 1, 1]  # 4 members: 2 to hear
    # ports: buildings, outdoor, steps, the stairs' ends, one link (stairs - A's door)
    assert list(site.port_building) == [0, 1, 0]
    assert list(site.port_outdoor) == [1, 1, 0]
    assert list(site.port_steps) == [0, 0, 20]
    assert (site.port_lo_x_m[2], site.port_hi_x_m[2], site.port_lo_x_m[0]) == (9.0, 11.0, 20.0)
    assert (list(site.link_a), list(site.link_b)) == ([0], [2])
    assert [c["identifiable"] for c in report["contexts"]] == [True] * 4
    # the site file takes it (every v3 rule) and reads it back
    path = tmp_path / "campus.sfsite"
    sitefile.write_site(path, site)
    got = sitefile.read_site(path)
    assert got.n_contexts == 4 and got.n_cdd == 6


def test_ble_readings_beat_the_model_and_an_empty_floor_is_reported():
    site = campus_site()
    b = campus_building()
    b.buildings.append(BuildingOutline("C", [(60.0, 0.0), (70.0, 0.0), (70.0, 10.0)], [1]))
    merge_building(site, b)
    # readings of the beacon: −55 and −65 at B/0's RPs, −70 at the outdoor RP
    placed = {
        "beacon_id": np.array([BEACON_B] * 3, np.int64),
        "x_m": np.array([35.2, 44.8, 25.1]),
        "y_m": np.array([5.0, 5.0, 5.0]),
        "floor": np.array([0, 0, 0], np.int64),
        "rssi_dbm": np.array([-55.0, -65.0, -70.0]),
        "n_total": np.asarray(3),
    }
    report = contexts.build_context_map(site, b, placed)
    assert _members(site, 3) == pytest.approx({BEACON_B: -60.0})  # max(−70 + 3, median −60)
    c = report["contexts"][-1]
    assert (c["building"], c["floor"], c["members"], c["identifiable"]) == ("C", 1, 0, False)
    from stridefix_analyzer.radiomap.show import format_context_map

    text = "\n".join(format_context_map(report))
    assert (
        "warning: context 4 (floor C floor 1) has no constellation member: the CLS cannot identify it" in text
    )


def test_hull_outline_keeps_every_point_margin_inside():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 30, 40), rng.uniform(0, 12, 40)
    outline = contexts.hull_outline(x, y)
    a = np.linspace(0, 2 * np.pi, 36, endpoint=False)
    ring_x = (x[:, None] + 4.99 * np.cos(a)).ravel()
    ring_y = (y[:, None] + 4.99 * np.sin(a)).ravel()
    assert contexts.inside(ring_x, ring_y, outline).all()  # every point within 5 m is inside
    far = contexts.inside(np.array([x.max() + 7.5]), np.array([y.mean()]), outline)
    assert not far[0]  # 7.5 m beyond the rightmost point: outside (the grown polygon exceeds 5 m by < 2 %)


def test_single_building_context_map_per_floor(tmp_path):
    site = campus_site()
    site.beacon_id, site.beacon_x_m, site.beacon_y_m = [BEACON_B], [40.0], [5.0]
    site.beacon_floor, site.beacon_rssi_1m_dbm = [1], [math.nan]
    site.ble_rssi_1m_dbm, site.ble_path_loss_exponent, site.ble_range_sigma_db = -59.0, 2.0, 6.0
    site.port_kind, site.port_x_m, site.port_y_m = [site_t.PORT_STAIRS], [10.0], [8.0]
    site.port_radius_m, site.port_floor_lo, site.port_floor_hi = [2.0], [0], [1]
    sitefile.set_counts(site)
    contexts.single_building_context_map(site, scheme="particle")
    assert site.n_buildings == 1 and site.n_outline >= 3
    assert list(site.context_kind) == [site_t.CONTEXT_FLOOR] * 2 and list(site.context_floor) == [0, 1]
    assert list(site.context_scheme) == [pose_t.SCHEME_PARTICLE] * 2
    assert list(site.context_method) == [fix_t.METHOD_WIFI, fix_t.METHOD_BLE]  # the beacon is on floor 1
    # floor 0 against floor 1 only (one building: every RP of a floor is its context's)
    assert set(_members(site, 0)) == {0x10, 0x15, 0x16, 0x17, 0x13, 0x14}
    assert list(site.port_steps) == [round(3.5 / contexts.STAIR_RISER_M)]  # 21 steps of 0.17 m
    assert list(site.port_building) == [0]
    sitefile.write_site(tmp_path / "one.sfsite", site)


def test_ble_threshold_clears_single_readings_across_the_slab():
    """A beacon heard across a floor slab (a stairwell, an atrium: ipin2023's basement beacons reach
    −64 dBm on the ground floor) passes a threshold set on mean levels in single live readings; the
    threshold sits above its loudest single reading elsewhere, and a beacon never that loud at home
    names no floor."""
    site = campus_site()
    near, far = 0xBEAC00000002, 0xBEAC00000003
    site.beacon_id, site.beacon_x_m, site.beacon_y_m = [near, far], [5.0, 15.0], [5.0, 5.0]
    site.beacon_floor, site.beacon_rssi_1m_dbm = [1, 1], [math.nan, math.nan]
    site.ble_rssi_1m_dbm, site.ble_path_loss_exponent, site.ble_range_sigma_db = -59.0, 2.0, 6.0
    sitefile.set_counts(site)
    # (beacon, x, floor, dBm): every reading sits at an RP (x, y 5)
    readings = [
        (near, 5.0, 1, -54.0),
        (near, 5.0, 1, -56.0),
        (near, 15.0, 1, -80.0),  # home: means -55, -80
        (near, 5.0, 0, -64.0),
        (near, 5.0, 0, -76.0),  # across the slab: mean -70, loudest -64
        (far, 15.0, 1, -60.0),
        (far, 15.0, 1, -62.0),  # home: mean -61, loudest -60
        (far, 15.0, 0, -85.0),
        (far, 15.0, 0, -61.0),  # across: mean -73, but one reading at -61
    ]
    placed = {
        "beacon_id": np.array([r[0] for r in readings], np.int64),
        "x_m": np.array([r[1] for r in readings]),
        "y_m": np.full(len(readings), 5.0),
        "floor": np.array([r[2] for r in readings], np.int64),
        "rssi_dbm": np.array([r[3] for r in readings]),
        "n_total": np.asarray(len(readings)),
    }
    contexts.single_building_context_map(site, ble_placed=placed)
    assert list(site.context_method) == [fix_t.METHOD_WIFI, fix_t.METHOD_BLE]
    # near: means alone give max(-70 + 3, median of -55 and -80 = -67.5) = -67; its single -64
    # elsewhere lifts that to -61, which its own -54 still reaches. far: the means say member at -61,
    # but -61 + 3 = -58 is above anything heard at home: no member.
    assert _members(site, 1) == pytest.approx({near: -61.0})


def _survey(msg):
    """Two floors of a building: AP 0xA loud on floor 0, 0xD on floor 1 only, 0xB everywhere alike."""
    points = [(0.0, 0.0, 0, -40.0), (4.0, 0.0, 0, -50.0), (0.0, 4.0, 1, -60.0), (4.0, 4.0, 1, -70.0)]
    events = []
    for k, (x, y, f, a_dbm) in enumerate(points):
        t0 = 10 * k * S
        events += [("TRUTH", msg.truth(t0, x, y, f)), ("TRUTH", msg.truth(t0 + 5 * S, x, y, f))]
        for j in range(3):
            aps = [(0xA, a_dbm), (0xB, -72.0)] + ([(0xD, -52.0)] if f == 1 else [])
            events.append(("WIFI", msg.scan(t0 + (j + 1) * S, aps, scan_id=3 * k + j)))
    return sorted(events, key=lambda e: e[1].t_us)


def test_radiomap_build_and_show_print_the_context_map(write_log, msg, tmp_path, stridefix_main, capsys):
    log = write_log("survey.lcmlog", _survey(msg))
    toml = tmp_path / "b.toml"
    toml.write_text(
        'format = "stridefix-building 1"\n[[building]]\nname = "H"\n'
        "outline = [[-5.0, -5.0], [10.0, -5.0], [10.0, 10.0], [-5.0, 10.0]]\nfloors = [0, 1]\n"
        '[[port]]\nkind = "door"\nx_m = -4.0\ny_m = 0.0\nradius_m = 1.0\nfloors = [0]\nbuilding = "H"\noutdoor = true\n'
    )
    out = tmp_path / "h.sfsite"
    assert stridefix_main(["radiomap", "build", log, "--out", out, "--building", toml]) == 0
    text = capsys.readouterr().out
    assert "contexts    3 in 1 building(s) (H), 0 port links, 2 constellation members" in text
    site = sitefile.read_site(out)
    assert_allclose(site.cdd_min_dbm, [-45.0, -52.0])  # 0xA on floor 0: max(−57, −45); 0xD: median
    assert list(site.cdd_id) == [0xA, 0xD] and list(site.cdd_context) == [1, 2]
    png = tmp_path / "h.png"
    assert stridefix_main(["radiomap", "show", out, "--png", png]) == 0
    shown = capsys.readouterr().out
    assert "   1 floor H          floor   0  LSD kalman + wifi  CDD wifi: 1 members, 1 to hear" in shown
    assert "port  0 door     floors 0..0  building H  outdoor" in shown
    assert png.stat().st_size > 0


def test_documented_campus_example_is_the_test_campus():
    """docs/examples/campus.toml parses to the campus of these tests (the documented example stays valid)."""
    import pathlib

    path = pathlib.Path(__file__).resolve().parents[3] / "docs" / "examples" / "campus.toml"
    got, want = read_building(path), campus_building()
    assert (got.buildings, got.port_extras, got.contexts) == (want.buildings, want.port_extras, want.contexts)
    assert got.ports == want.ports and [b[:4] for b in got.beacons] == [b[:4] for b in want.beacons]


def _members_reference(ids, rps, means, own):
    """The constellation rules one id at a time (the loop the vectorised builder replaced)."""
    out, mine = [], own[rps]
    for ident in np.unique(ids[mine]):
        sel = ids == ident
        at_own, elsewhere = means[sel & mine], means[sel & ~mine]
        loud = float(at_own.max())
        if elsewhere.size and not loud >= float(elsewhere.max()) + contexts.CDD_MARGIN_DB:
            continue
        floor_dbm = float(np.median(at_own))
        if elsewhere.size:
            floor_dbm = max(float(elsewhere.max()) + contexts.CDD_ABOVE_ELSEWHERE_DB, floor_dbm)
        out.append((int(ident), floor_dbm))
    return out


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_members_of_every_id_at_once_follow_the_rules_one_id_at_a_time():
    """GIVEN random per-(id, RP) levels (ties, NaN and -inf among them), WHEN the members are taken
    for every id at once, THEN they are the per-id rules' members and levels, exactly."""
    rng = np.random.default_rng(7)
    for trial in range(500):
        n, n_rp = int(rng.integers(0, 60)), int(rng.integers(1, 12))
        ids = rng.integers(0, int(rng.integers(1, 10)), n).astype(np.int64)
        rps = rng.integers(0, n_rp, n)
        means = np.round(rng.normal(-70.0, 6.0, n), int(rng.integers(0, 2)))
        if trial % 3 == 0 and n:
            means[rng.integers(0, n, 2)] = np.nan
        if trial % 5 == 0 and n:
            means[rng.integers(0, n, 1)] = -np.inf
        own = rng.random(n_rp) < rng.random()
        got, want = contexts._members(ids, rps, means, own), _members_reference(ids, rps, means, own)
        assert [i for i, _ in got] == [i for i, _ in want], trial
        for (_, g), (_, w) in zip(got, want, strict=True):
            assert g == w or (math.isnan(g) and math.isnan(w)), trial
