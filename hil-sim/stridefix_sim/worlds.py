"""The built-in worlds by name (``world.name`` in a scenario): ``default`` (world.py, the two-floor
office), ``aadr2015`` (world_aadr2015.py, the foyer), ``campus`` (world_campus.py, a building with
an outdoor stretch, beacons and landmarks) and ``campus2`` (world_campus2.py, two buildings joined by
an outdoor path: three floors with Wi-Fi, stairs and an elevator; one floor with BLE)."""

from __future__ import annotations

from .world import World, default_world
from .world_aadr2015 import aadr2015_world
from .world_campus import campus_world
from .world_campus2 import campus2_world

WORLDS = {
    "default": default_world,
    "aadr2015": aadr2015_world,
    "campus": campus_world,
    "campus2": campus2_world,
}


def load_world(name: str, map_rotation_deg: float) -> World:
    if name not in WORLDS:
        raise KeyError(f"unknown world {name!r} (known: {', '.join(sorted(WORLDS))})")
    return WORLDS[name](map_rotation_deg=map_rotation_deg)
