"""The building description ``building.toml`` (docs/building.md): geo-reference, BLE model, walls,
ports and beacons of a user's own building, merged into a site file by ``stridefix radiomap build
--building FILE``; also the context map's tables ([[building]], the [[port]] extras,
[[context]]: :mod:`.building_contexts`, built into the site by :mod:`.contexts`).

:func:`read_building` parses and checks it (tomllib); every error names the file, the entry
(``[[wall]] 3``) and the field. :func:`merge_building` writes it into a ``site_t`` (walls per segment,
beacons sorted by id, lat/lon beacons projected about the geo origin with
:func:`~stridefix_analyzer.datasets.gsd_convert.project` and turned into the map frame).
:func:`building_toml` writes a :class:`Building` back as TOML (the simulator's side).
Cost: O(entries).
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from typing import Any

import numpy as np
from stridefix_common.building import (
    FORMAT,
    PORT_EXTRA_KEYS,
    PORT_KIND_CODES,
    BuildingOutline,
    PortExtra,
    port_extra_lines,
)
from stridefix_common.geodesy import project

from stridefix_analyzer.datasets.rawwalk import bssid_to_int
from stridefix_analyzer.radiomap.building_contexts import (
    ContextSpec,
    context_tables_toml,
    parse_context_tables,
    parse_port_extra,
)

__all__ = [
    "Building",
    "BuildingError",
    "BuildingOutline",
    "ContextSpec",
    "PortExtra",
    "building_toml",
    "merge_building",
    "read_building",
]


class BuildingError(ValueError):
    """A building description is unreadable or breaks a rule: ``"<file>: <entry>: <field>: <what>"``."""


@dataclasses.dataclass
class Building:
    """A parsed building description (map frame [m]; floors are indices)."""

    geo: dict[str, float] | None = None  # origin_lat_deg, origin_lon_deg, origin_alt_m, rotation_deg
    ble: dict[str, float] | None = None  # rssi_1m_dbm, path_loss_exponent, range_sigma_db
    walls: list[tuple[float, float, float, float, int]] = dataclasses.field(default_factory=list)
    ports: list[tuple[int, float, float, float, int, int]] = dataclasses.field(default_factory=list)
    beacons: list[tuple[int, float, float, int, float]] = dataclasses.field(default_factory=list)
    buildings: list[BuildingOutline] = dataclasses.field(default_factory=list)
    port_extras: list[PortExtra] = dataclasses.field(default_factory=list)  # [] or one per ports row
    contexts: list[ContextSpec] = dataclasses.field(default_factory=list)

    def floors(self) -> set[int]:
        """Every floor a wall, port, beacon, building or context names."""
        out = {w[4] for w in self.walls} | {b[3] for b in self.beacons}
        for p in self.ports:
            out |= set(range(p[4], p[5] + 1))
        for b in self.buildings:
            out |= set(b.floors)
        return out | {c.floor for c in self.contexts if c.floor is not None}


def _num(path: str, entry: str, table: dict[str, Any], key: str, default: float | None = None) -> float:
    if key not in table:
        if default is not None:
            return default
        raise BuildingError(f"{path}: {entry}: {key}: missing")
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise BuildingError(f"{path}: {entry}: {key}: {v!r} is not a finite number")
    return float(v)


def _int(path: str, entry: str, table: dict[str, Any], key: str) -> int:
    v = table.get(key)
    if isinstance(v, bool) or not isinstance(v, int):
        raise BuildingError(
            f"{path}: {entry}: {key}: {'missing' if v is None else repr(v) + ' is not an integer'}"
        )
    if not -32768 <= v <= 32767:
        raise BuildingError(f"{path}: {entry}: {key}: {v} outside the int16 floor range")
    return v


def _unknown(path: str, entry: str, table: dict[str, Any], known: set[str]) -> None:
    extra = sorted(set(table) - known)
    if extra:
        raise BuildingError(f"{path}: {entry}: {extra[0]}: unknown field (known: {', '.join(sorted(known))})")


def _geo(path: str, doc: dict[str, Any]) -> dict[str, float] | None:
    g = doc.get("geo")
    if g is None:
        return None
    _unknown(path, "[geo]", g, {"origin_lat_deg", "origin_lon_deg", "origin_alt_m", "rotation_deg"})
    out = {
        "origin_lat_deg": _num(path, "[geo]", g, "origin_lat_deg"),
        "origin_lon_deg": _num(path, "[geo]", g, "origin_lon_deg"),
        "origin_alt_m": _num(path, "[geo]", g, "origin_alt_m", 0.0),
        "rotation_deg": _num(path, "[geo]", g, "rotation_deg", 0.0),
    }
    if not -90.0 <= out["origin_lat_deg"] <= 90.0:
        raise BuildingError(f"{path}: [geo]: origin_lat_deg: {out['origin_lat_deg']:g} outside -90..90")
    if not -180.0 <= out["origin_lon_deg"] <= 180.0:
        raise BuildingError(f"{path}: [geo]: origin_lon_deg: {out['origin_lon_deg']:g} outside -180..180")
    return out


def _ble(path: str, doc: dict[str, Any]) -> dict[str, float] | None:
    b = doc.get("ble")
    if b is None:
        return None
    keys = ("rssi_1m_dbm", "path_loss_exponent", "range_sigma_db")
    _unknown(path, "[ble]", b, set(keys))
    out = {k: _num(path, "[ble]", b, k) for k in keys}
    for k in keys[1:]:
        if not out[k] > 0:
            raise BuildingError(f"{path}: [ble]: {k}: {out[k]:g} must be > 0")
    return out


def _walls(path: str, doc: dict[str, Any]) -> list[tuple[float, float, float, float, int]]:
    out = []
    for i, w in enumerate(doc.get("wall", [])):
        entry = f"[[wall]] {i + 1}"
        _unknown(path, entry, w, {"floor", "points", "closed"})
        floor = _int(path, entry, w, "floor")
        pts = w.get("points")
        if not isinstance(pts, list) or len(pts) < 2:
            raise BuildingError(f"{path}: {entry}: points: needs a list of at least two [x, y] points")
        xy = []
        for k, p in enumerate(pts):
            if not (isinstance(p, list) and len(p) == 2):
                raise BuildingError(f"{path}: {entry}: points[{k}]: {p!r} is not [x, y]")
            xy.append(tuple(_num(path, entry, {f"points[{k}]": c}, f"points[{k}]") for c in p))
        closed = w.get("closed", False)
        if not isinstance(closed, bool):
            raise BuildingError(f"{path}: {entry}: closed: {closed!r} is not true or false")
        if closed:
            xy.append(xy[0])
        for k in range(len(xy) - 1):
            (x0, y0), (x1, y1) = xy[k], xy[k + 1]
            if (x0, y0) == (x1, y1):
                raise BuildingError(f"{path}: {entry}: points[{k}]: zero-length segment at ({x0:g}, {y0:g})")
            out.append((x0, y0, x1, y1, floor))
    return out


def _ports(
    path: str, doc: dict[str, Any]
) -> tuple[list[tuple[int, float, float, float, int, int]], list[PortExtra | None], list[str]]:
    """The ports' rows, their extras (None: none given) and their kinds' names."""
    out = []
    extras: list[PortExtra | None] = []
    kinds: list[str] = []
    for i, p in enumerate(doc.get("port", [])):
        entry = f"[[port]] {i + 1}"
        _unknown(path, entry, p, {"kind", "x_m", "y_m", "radius_m", "floors"} | PORT_EXTRA_KEYS)
        kind = p.get("kind")
        if kind not in PORT_KIND_CODES:
            raise BuildingError(f"{path}: {entry}: kind: {kind!r} is not one of door, stairs, elevator")
        x, y, r = (_num(path, entry, p, k) for k in ("x_m", "y_m", "radius_m"))
        if not r > 0:
            raise BuildingError(f"{path}: {entry}: radius_m: {r:g} must be > 0")
        floors = p.get("floors")
        if not (
            isinstance(floors, list)
            and floors
            and all(isinstance(f, int) and not isinstance(f, bool) for f in floors)
        ):
            raise BuildingError(f"{path}: {entry}: floors: {floors!r} is not a list of floor indices")
        if kind == "door" and len(set(floors)) != 1:
            raise BuildingError(f"{path}: {entry}: floors: a door joins one floor, got {floors}")
        if kind != "door" and len(set(floors)) < 2:
            raise BuildingError(
                f"{path}: {entry}: floors: {kind} must join at least two floors, got {floors}"
            )
        out.append((PORT_KIND_CODES[kind], x, y, r, min(floors), max(floors)))
        extras.append(parse_port_extra(path, entry, p, kind, BuildingError))
        kinds.append(kind)
    return out, extras, kinds


def _beacons(
    path: str, doc: dict[str, Any], geo: dict[str, float] | None
) -> list[tuple[int, float, float, int, float]]:
    out = []
    seen: dict[int, int] = {}
    for i, b in enumerate(doc.get("beacon", [])):
        entry = f"[[beacon]] {i + 1}"
        _unknown(path, entry, b, {"id", "x_m", "y_m", "lat_deg", "lon_deg", "floor", "rssi_1m_dbm"})
        try:
            ident = bssid_to_int(str(b.get("id", "")))
        except ValueError:
            raise BuildingError(
                f"{path}: {entry}: id: {b.get('id')!r} is not a MAC aa:bb:cc:dd:ee:ff"
            ) from None
        if ident in seen:
            raise BuildingError(f"{path}: {entry}: id: {b['id']} already given in [[beacon]] {seen[ident]}")
        seen[ident] = i + 1
        if "x_m" in b or "y_m" in b:
            x, y = _num(path, entry, b, "x_m"), _num(path, entry, b, "y_m")
        elif "lat_deg" in b or "lon_deg" in b:
            if geo is None:
                raise BuildingError(f"{path}: {entry}: lat_deg: a geo-located beacon needs [geo]")
            x, y = to_map_frame(geo, _num(path, entry, b, "lat_deg"), _num(path, entry, b, "lon_deg"))
        else:
            raise BuildingError(f"{path}: {entry}: x_m: missing (or lat_deg/lon_deg with [geo])")
        rssi = _num(path, entry, b, "rssi_1m_dbm", math.nan) if "rssi_1m_dbm" in b else math.nan
        out.append((ident, x, y, _int(path, entry, b, "floor"), rssi))
    return out


def to_map_frame(geo: dict[str, float], lat_deg: float, lon_deg: float) -> tuple[float, float]:
    """WGS-84 → map frame [m]: local east-north about the origin, turned by −rotation (the map frame
    is the east-north frame turned counter-clockwise by ``rotation_deg``)."""
    e, n = project([lat_deg], [lon_deg], geo["origin_lat_deg"], geo["origin_lon_deg"])
    a = math.radians(geo["rotation_deg"])
    c, s = math.cos(a), math.sin(a)
    return float(c * e[0] + s * n[0]), float(-s * e[0] + c * n[0])


def read_building(path: str | os.PathLike[str]) -> Building:
    """Parse and check ``building.toml``. Raises :class:`BuildingError` naming file, entry and field."""
    path = os.fspath(path)
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except OSError as exc:
        raise BuildingError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise BuildingError(f"{path}: not TOML: {exc}") from None
    except UnicodeDecodeError as exc:  # tomllib decodes the bytes itself: a PNG, UTF-16, junk
        raise BuildingError(f"{path}: not TOML: not UTF-8 text (byte {exc.start}: {exc.reason})") from None
    if doc.get("format") != FORMAT:
        raise BuildingError(f"{path}: format: {doc.get('format')!r}, expected {FORMAT!r}")
    _unknown(
        path, "top level", doc, {"format", "geo", "ble", "wall", "port", "beacon", "building", "context"}
    )
    geo = _geo(path, doc)
    ports, extras, kinds = _ports(path, doc)
    buildings, port_extras, contexts = parse_context_tables(path, doc, extras, kinds, BuildingError)
    return Building(
        geo,
        _ble(path, doc),
        _walls(path, doc),
        ports,
        _beacons(path, doc, geo),
        buildings,
        port_extras,
        contexts,
    )


def merge_building(site: Any, building: Building, source: str = "") -> dict[str, int]:
    """Write the building's content into ``site`` (replacing walls, ports, beacons; geo and BLE model
    when given). Returns the counts merged. Floors outside the site's are the site file's error."""
    from stridefix_analyzer.io.site_v3 import V3_ARRAYS
    from stridefix_analyzer.io.sitefile import set_counts

    if building.geo is not None:
        g = building.geo
        site.has_geo = True
        site.origin_lat_deg, site.origin_lon_deg = g["origin_lat_deg"], g["origin_lon_deg"]
        site.origin_alt_m, site.geo_rotation_deg = g["origin_alt_m"], g["rotation_deg"]
    if building.walls:
        cols = list(zip(*building.walls))
        site.wall_x0_m, site.wall_y0_m, site.wall_x1_m, site.wall_y1_m = (list(c) for c in cols[:4])
        site.wall_floor = list(cols[4])
    if building.ports:
        cols = list(zip(*building.ports))
        site.port_kind, site.port_x_m, site.port_y_m, site.port_radius_m = (list(c) for c in cols[:4])
        site.port_floor_lo, site.port_floor_hi = list(cols[4]), list(cols[5])
        for name in V3_ARRAYS["n_ports"]:
            setattr(site, name, [])  # the old ports' extras: neutral ones (or contexts.py's) instead
    if building.beacons:
        rows = sorted(building.beacons)
        site.beacon_id = [r[0] for r in rows]
        site.beacon_x_m, site.beacon_y_m = [r[1] for r in rows], [r[2] for r in rows]
        site.beacon_floor, site.beacon_rssi_1m_dbm = [r[3] for r in rows], [r[4] for r in rows]
    if building.ble is not None:
        b = building.ble
        site.ble_rssi_1m_dbm = b["rssi_1m_dbm"]
        site.ble_path_loss_exponent, site.ble_range_sigma_db = b["path_loss_exponent"], b["range_sigma_db"]
    set_counts(site)
    if source:
        site.source = f"{site.source}; building {source}"
    return {"walls": len(building.walls), "ports": len(building.ports), "beacons": len(building.beacons)}


def building_toml(b: Building) -> str:
    """``building.toml`` text of ``b`` (one [[wall]] per segment; beacons by x_m, y_m; the context
    map's [[building]], port extras and [[context]] when given): :func:`read_building` of it gives
    ``b`` again."""
    names = {v: k for k, v in PORT_KIND_CODES.items()}
    out = [f'format = "{FORMAT}"']
    if b.geo:
        out += ["", "[geo]", *(f"{k} = {v!r}" for k, v in b.geo.items())]
    if b.ble:
        out += ["", "[ble]", *(f"{k} = {v!r}" for k, v in b.ble.items())]
    for x0, y0, x1, y1, f in b.walls:
        out += ["", "[[wall]]", f"floor = {f}", f"points = [[{x0!r}, {y0!r}], [{x1!r}, {y1!r}]]"]
    if b.port_extras and len(b.port_extras) != len(b.ports):
        raise ValueError(f"{len(b.port_extras)} port extras for {len(b.ports)} ports (give none or one each)")
    for i, (kind, x, y, r, lo, hi) in enumerate(b.ports):
        floors = ", ".join(str(f) for f in range(lo, hi + 1))
        out += ["", "[[port]]", f'kind = "{names[kind]}"', f"x_m = {x!r}", f"y_m = {y!r}"]
        out += [f"radius_m = {r!r}", f"floors = [{floors}]"]
        if b.port_extras:
            out += port_extra_lines(b.port_extras[i], (x, y))
    for ident, x, y, f, rssi in b.beacons:
        mac = ":".join(f"{(ident >> s) & 0xFF:02X}" for s in range(40, -1, -8))
        out += ["", "[[beacon]]", f'id = "{mac}"', f"x_m = {x!r}", f"y_m = {y!r}", f"floor = {f}"]
        if not np.isnan(rssi):
            out.append(f"rssi_1m_dbm = {rssi!r}")
    out += context_tables_toml(b.buildings, b.contexts)
    return "\n".join(out) + "\n"
