"""The building description (building.toml, ``stridefix-building 1``) round-trips a world: parsed with
tomllib it gives back the world's walls, ports, beacons and geo-reference."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from stridefix_sim.building import FORMAT, building_text
from stridefix_sim.scenario import builtin_scenario
from stridefix_sim.worlds import WORLDS, load_world


@pytest.mark.parametrize("name", sorted(WORLDS))
def test_building_round_trips_the_world(name):
    world = load_world(name, 20.0)
    ble = builtin_scenario("campus").data["ble"]
    doc = tomllib.loads(building_text(world, ble))
    assert doc["format"] == FORMAT
    # walls: every segment once per floor of its building (a world without outlines: every floor),
    # coordinates as the world has them (to 1 µm)
    walls = doc["wall"]
    floors_of = [
        next((o.floors for o in world.outlines if o.holds(w[0], w[1]) and o.holds(w[2], w[3])), None)
        for w in world.walls_m
    ]
    assert all(f is not None for f in floors_of) or not world.outlines
    for f in range(world.n_floors):
        on = [fl is None or f in fl for fl in floors_of]
        got = np.array([[*w["points"][0], *w["points"][1]] for w in walls if w["floor"] == f])
        np.testing.assert_allclose(got, world.walls_m[on], atol=1e-6)
    assert len(walls) == sum(world.n_floors if fl is None else len(fl) for fl in floors_of)
    assert all(w["closed"] is False and len(w["points"]) == 2 for w in walls)
    # ports: stairs, elevator, each door to the outside
    kinds = [p["kind"] for p in doc.get("port", [])]
    assert kinds.count("stairs") == (world.stairs is not None)
    assert kinds.count("elevator") == (world.elevator is not None)
    doors = [p for p in doc.get("port", []) if p["kind"] == "door"]
    assert [(p["x_m"], p["y_m"], p["floors"]) for p in doors] == [
        (d.x_m, d.y_m, [d.floor]) for d in world.doors
    ]
    for p in doc.get("port", []):
        assert p["radius_m"] > 0 and p["floors"] == sorted(p["floors"])
        assert all(0 <= f < world.n_floors for f in p["floors"])
    # beacons: MAC text, position, floor, measured power
    beacons = doc.get("beacon", [])
    assert len(beacons) == len(world.beacons)
    for b, w in zip(beacons, world.beacons):
        assert int(b["id"].replace(":", ""), 16) == w.mac
        assert (b["x_m"], b["y_m"], b["floor"], b["rssi_1m_dbm"]) == (w.x_m, w.y_m, w.floor, w.rssi_1m_dbm)
    # BLE model and geo-reference
    assert doc["ble"]["path_loss_exponent"] == ble["path_loss_exponent"]
    assert doc["ble"]["range_sigma_db"] == ble["shadowing_db"]
    assert doc["geo"]["rotation_deg"] == world.map_rotation_deg
    if world.geo is not None:
        assert doc["geo"]["origin_lat_deg"] == world.geo.origin_lat_deg
        assert doc["geo"]["origin_alt_m"] == world.geo.origin_alt_m
        assert math.isfinite(doc["geo"]["origin_lon_deg"])


def test_campus_building_has_its_sources():
    doc = tomllib.loads(building_text(load_world("campus", 20.0)))
    assert len(doc["beacon"]) >= 6 and len({b["id"] for b in doc["beacon"]}) == len(doc["beacon"])
    assert [p["kind"] for p in doc["port"]] == ["door", "door"]
