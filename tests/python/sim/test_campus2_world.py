"""The campus2 world (the multi-scheme controller's SIL campus): its geometry is consistent
— doors in their outline's exterior wall, the staircase and the elevator inside A, Wi-Fi only in A
(every floor), BLE only in B, an outdoor path of 50-80 m outside both footprints — and its building
description carries the context map (outlines, per-building wall floors, port extras and links)."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from stridefix_sim.building import building_text
from stridefix_sim.radio import walls_crossed
from stridefix_sim.route import Polyline
from stridefix_sim.world_campus2 import PATH_M
from stridefix_sim.world_sources import inside
from stridefix_sim.worlds import load_world


@pytest.fixture(scope="module")
def world():
    return load_world("campus2", 20.0)


@pytest.fixture(scope="module")
def outline(world):
    return {o.name: o for o in world.outlines}


def _on_wall(world, x: float, y: float, tol_m: float = 1e-6) -> bool:
    """Does the point lie on a wall segment?"""
    w = world.walls_m
    a, b = w[:, 0:2], w[:, 2:4]
    ab = b - a
    u = np.clip(np.sum((np.array([x, y]) - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    d = np.hypot(*(np.array([x, y]) - (a + u[:, None] * ab)).T)
    return bool(np.any(d <= tol_m))


def test_two_buildings_a_three_floors_b_one(world, outline):
    assert set(outline) == {"A", "B"}
    assert outline["A"].floors == (0, 1, 2) and outline["B"].floors == (0,)
    assert world.n_floors == 3
    # the footprint (GNSS indoors/outdoors) is the union of the outlines
    np.testing.assert_array_equal(world.footprint_m, [o.rect_m for o in world.outlines])


def test_each_door_is_a_gap_in_its_outline_wall(world, outline):
    assert [(d.name, d.landmark_id) for d in world.doors] == [("A-door", 1), ("B-door", 2)]
    for door, name in zip(world.doors, ("A", "B")):
        x0, y0, x1, y1 = outline[name].rect_m
        # on the outline's west or east side, between its corners
        assert door.x_m in (x0, x1) and y0 < door.y_m < y1
        half = door.width_m / 2
        # THEN the gap is open over its width and the exterior wall closes it just beyond
        for dy in np.linspace(-half + 0.05, half - 0.05, 7):
            assert not _on_wall(world, door.x_m, door.y_m + dy)
        assert _on_wall(world, door.x_m, door.y_m + half + 0.05)
        assert _on_wall(world, door.x_m, door.y_m - half - 0.05)
        # and one can walk straight through it: 2 m outside to 2 m inside crosses no wall
        sgn = 1.0 if door.x_m == x1 else -1.0
        assert walls_crossed(door.x_m + 2 * sgn, door.y_m, door.x_m - 2 * sgn, door.y_m, world.walls_m) == 0


def test_stairs_and_elevator_inside_a(world, outline):
    a = outline["A"]
    st, el = world.stairs, world.elevator
    for x, y in (st.flight1_start, st.flight1_end, st.flight2_start, st.flight2_end, (el.x_m, el.door_y_m)):
        assert a.holds(x, y) and not outline["B"].holds(x, y)
    assert 2 * st.risers_per_flight * st.riser_m == pytest.approx(world.storey_m)


def test_wifi_on_every_floor_of_a_only_ble_in_b_only(world, outline):
    aps = world.aps
    for f in outline["A"].floors:
        on = [ap for ap in aps if ap.floor == f]
        assert len(on) >= 6 and all(outline["A"].holds(ap.x_m, ap.y_m) for ap in on)
    assert len({ap.bssid for ap in aps}) == len(aps)
    assert len(world.beacons) >= 6
    assert all(outline["B"].holds(b.x_m, b.y_m) and b.floor == 0 for b in world.beacons)
    assert not any(outline["B"].holds(ap.x_m, ap.y_m) for ap in aps)


def test_outdoor_path_joins_the_doors_outside_both_buildings(world):
    path = Polyline(PATH_M, 0.8)
    assert 50.0 <= path.length_m <= 80.0
    a, b = world.doors
    assert PATH_M[0] == (a.x_m, a.y_m) and PATH_M[-1] == (b.x_m, b.y_m)
    d = np.linspace(0.5, path.length_m - 0.5, 400)
    x, y, _, _ = path.pose(d)
    assert not inside(world.footprint_m, x, y).any()
    assert walls_crossed(x[:-1], y[:-1], x[1:], y[1:], world.walls_m).sum() == 0


def test_building_description_has_the_context_map(world, outline):
    doc = tomllib.loads(building_text(world))
    assert [(b["name"], b["floors"]) for b in doc["building"]] == [("A", [0, 1, 2]), ("B", [0])]
    for b in doc["building"]:
        x0, y0, x1, y1 = outline[b["name"]].rect_m
        assert b["outline"] == [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]  # counter-clockwise
    # B's walls only on floor 0; A's on floors 0, 1, 2
    b_walls = [w for w in doc["wall"] if w["points"][0][0] >= outline["B"].rect_m[0]]
    assert b_walls and {w["floor"] for w in b_walls} == {0}
    assert {w["floor"] for w in doc["wall"] if w["points"][0][0] <= outline["A"].rect_m[2]} == {0, 1, 2}
    ports = {p["name"]: p for p in doc["port"]}
    assert set(ports) == {"A-stairs", "A-elevator", "A-door", "B-door"}
    st = ports["A-stairs"]
    assert (st["kind"], st["building"], st["floors"], st["steps"]) == ("stairs", "A", [0, 1], 20)
    assert st["ends"] == [list(world.stairs.flight1_start), list(world.stairs.flight2_end)]
    assert st.get("outdoor", False) is False
    el = ports["A-elevator"]
    assert (el["kind"], el["building"], el["floors"]) == ("elevator", "A", [0, 1, 2])
    for name, b in (("A-door", "A"), ("B-door", "B")):
        assert (ports[name]["kind"], ports[name]["building"], ports[name]["outdoor"]) == ("door", b, True)
    # the staircase's ends lie within its port's disc (where the controller recalibrates)
    for x, y in st["ends"]:
        assert math.hypot(x - st["x_m"], y - st["y_m"]) <= st["radius_m"]
    # links: symmetric, to existing ports; the doors reach each other outdoors, A's ports each other
    for name, p in ports.items():
        assert all(name in ports[n]["links"] for n in p["links"])
    assert set(ports["A-door"]["links"]) == {"A-stairs", "A-elevator", "B-door"}
    assert set(ports["B-door"]["links"]) == {"A-door"}
    assert "context" not in doc  # the build's derivation fits: no override
