"""The building description of a world (``building.toml``, format ``stridefix-building 1``): what the
site builder (``stridefix radiomap build ... --building FILE``) reads besides the radio survey.

    format = "stridefix-building 1"
    [geo]    origin_lat_deg, origin_lon_deg, origin_alt_m, rotation_deg (map = local east-north turned
             counter-clockwise by this)
    [ble]    rssi_1m_dbm, path_loss_exponent, range_sigma_db (the beacons' log-distance model)
    [[wall]] floor, points = [[x, y], ...] (map frame [m]), closed
    [[port]] kind (door | stairs | elevator), x_m, y_m, radius_m, floors = [lo, ..., hi]
    [[beacon]] id ("aa:bb:cc:dd:ee:ff"), x_m, y_m, floor, rssi_1m_dbm

Every wall segment of the world is one ``[[wall]]`` per floor (every floor has the same plan; two points,
open). Ports: the stairwell (a disc over both flights and the landing), the elevator cab (a disc over
the cab) and each door to the outside (a disc ``width/2 + 0.5 m`` about its centre). [ble] holds the
scenario's BLE model (``ble.path_loss_exponent``, ``ble.shadowing_db``) and the beacons' mean measured
power; each beacon keeps its own. A world without a geo-reference gets the default one of
``world_sources.GeoRef`` (rotation = its map rotation). Written by every ``stridefix sim`` run into
``DIR/building.toml``.

A world with building outlines (world_parts.py, e.g. ``campus2``) adds the context map of
docs/building.md (constructed as :mod:`stridefix_common.building`'s ``BuildingOutline`` and ``PortExtra``): one
``[[building]]`` per outline (its rectangle's corners counter-clockwise, its floors); each wall on the
floors of the building that holds it; and each port's extras — its name (``<building>-stairs``,
``<building>-elevator``, the door's name), its building, ``outdoor = true`` for a door to the outside,
a staircase's steps end to end (its risers) and its two ends (where the first flight starts on the
lower floor and the last one ends on the upper floor), and its links: the ports reachable from it
without passing another (every port of its building on a floor they share, and outdoors every door to
the outside). No ``[[context]]``: the build's derivation fits the world (BLE on B's floor, Wi-Fi on
A's, GNSS outdoors).
"""

from __future__ import annotations

import math
from pathlib import Path

from stridefix_common.building import FORMAT, BuildingOutline, PortExtra, port_extra_lines

from .scenario_sources import SOURCE_DEFAULTS
from .world import World
from .world_parts import building_of
from .world_sources import GeoRef

DOOR_MARGIN_M = 0.5  # a door's port reaches this far beyond the door's half width


def _num(v: float) -> str:
    return repr(round(float(v), 6))


def port_rows(world: World) -> list[tuple[str, float, float, float, list[int], PortExtra]]:
    """The world's ports (kind, x, y, radius, floors) with their context-map extras (see above)."""
    rows = []
    for kind, x, y, r, floors in _ports(world):
        o = building_of(world.outlines, x, y)
        b = o.name if o is not None else None
        extra = PortExtra(building=b)
        st = world.stairs
        if kind == "stairs" and st is not None:
            extra.name, extra.steps = f"{b}-stairs", 2 * st.risers_per_flight
            extra.end_lo, extra.end_hi = st.flight1_start, st.flight2_end
        elif kind == "elevator":
            extra.name = f"{b}-elevator"
        rows.append((kind, x, y, r, floors, extra))
    for row, d in zip(rows[len(rows) - len(world.doors) :], world.doors):  # (_ports: doors last)
        row[5].name, row[5].outdoor = d.name, True
    for *_, floors, extra in rows:
        extra.links = [
            e.name
            for *_, fl, e in rows
            if e is not extra
            and ((e.building == extra.building and set(fl) & set(floors)) or (extra.outdoor and e.outdoor))
        ]
    return rows


def outlines(world: World) -> list[BuildingOutline]:
    return [BuildingOutline(o.name, o.corners(), list(o.floors)) for o in world.outlines]


def _wall_floors(world: World, wall) -> list[int]:
    """A wall's floors: its building's (both ends inside the outline), else every floor."""
    for o in world.outlines:
        if bool(o.holds(wall[0], wall[1])) and bool(o.holds(wall[2], wall[3])):
            return list(o.floors)
    return list(range(world.n_floors))


def _ports(world: World) -> list[tuple[str, float, float, float, list[int]]]:
    out = []
    st = world.stairs
    if st is not None:
        xs = (st.flight1_start[0], st.flight1_end[0], st.flight2_start[0], st.flight2_end[0])
        ys = (st.flight1_start[1], st.flight1_end[1], st.flight2_start[1], st.flight2_end[1], st.landing_y_m)
        cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
        r = math.hypot(max(xs) - cx, max(ys) - cy) + DOOR_MARGIN_M
        out.append(("stairs", cx, cy, r, [0, 1]))
    el = world.elevator
    if el is not None:
        out.append(("elevator", el.x_m, el.door_y_m, el.half_m * math.sqrt(2.0), list(range(world.n_floors))))
    for d in world.doors:
        out.append(("door", d.x_m, d.y_m, d.width_m / 2 + DOOR_MARGIN_M, [d.floor]))
    return out


def building_text(world: World, ble: dict | None = None) -> str:
    """The TOML text of ``world``'s building description (``ble``: the scenario's [ble] table)."""
    b = ble if ble is not None else SOURCE_DEFAULTS["ble"]
    geo = world.geo if world.geo is not None else GeoRef(rotation_deg=world.map_rotation_deg)
    p1 = [bc.rssi_1m_dbm for bc in world.beacons]
    lines = [
        f'format = "{FORMAT}"',
        f"# world {world.name}: {world.description}" if world.description else f"# world {world.name}",
        "",
        "[geo]",
        f"origin_lat_deg = {geo.origin_lat_deg!r}",
        f"origin_lon_deg = {geo.origin_lon_deg!r}",
        f"origin_alt_m = {geo.origin_alt_m!r}",
        f"rotation_deg = {geo.rotation_deg!r}",
        "",
        "[ble]",
        f"rssi_1m_dbm = {_num(sum(p1) / len(p1) if p1 else -59.0)}",
        f"path_loss_exponent = {_num(b['path_loss_exponent'])}",
        f"range_sigma_db = {_num(b['shadowing_db'])}",
    ]
    walls = world.walls_m.tolist()
    wall_floors = [_wall_floors(world, w) for w in walls]
    for floor in range(world.n_floors):
        for (x0, y0, x1, y1), fl in zip(walls, wall_floors):
            if floor not in fl:
                continue
            lines += [
                "",
                "[[wall]]",
                f"floor = {floor}",
                f"points = [[{_num(x0)}, {_num(y0)}], [{_num(x1)}, {_num(y1)}]]",
                "closed = false",
            ]
    for bo in outlines(world):
        pts = ", ".join(f"[{_num(x)}, {_num(y)}]" for x, y in bo.outline)
        lines += ["", "[[building]]", f'name = "{bo.name}"', f"outline = [{pts}]"]
        lines.append(f"floors = [{', '.join(str(f) for f in bo.floors)}]")
    for kind, x, y, r, floors, extra in port_rows(world):
        lines += [
            "",
            "[[port]]",
            f'kind = "{kind}"',
            f"x_m = {_num(x)}",
            f"y_m = {_num(y)}",
            f"radius_m = {_num(r)}",
            f"floors = [{', '.join(str(f) for f in floors)}]",
        ]
        if world.outlines:
            lines += port_extra_lines(extra, (x, y))
    for bc in world.beacons:
        lines += [
            "",
            "[[beacon]]",
            f'id = "{bc.mac_text}"',
            f"x_m = {_num(bc.x_m)}",
            f"y_m = {_num(bc.y_m)}",
            f"floor = {bc.floor}",
            f"rssi_1m_dbm = {_num(bc.rssi_1m_dbm)}",
        ]
    return "\n".join(lines) + "\n"


def write_building(world: World, path: Path, ble: dict | None = None) -> None:
    Path(path).write_text(building_text(world, ble), encoding="utf-8")
