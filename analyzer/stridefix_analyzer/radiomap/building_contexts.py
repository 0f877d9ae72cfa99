"""The context-map tables of ``building.toml`` (docs/building.md): ``[[building]]`` (outline and
floors), the ``[[port]]`` extras (name, building, outdoor, steps, ends, links) and ``[[context]]``
(a context's scheme and method overrides), for the multi-scheme controller (Jäger, Süß, Becker
§III-C). :mod:`.building` parses the rest of the file and calls :func:`parse_context_tables`;
:func:`context_tables_toml` writes these tables back. Errors name the file, the entry and the field
(:class:`~.building.BuildingError` via the ``error`` class passed in). Cost: O(entries + links).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from stridefix import pose_t
from stridefix_common.building import (
    PORT_EXTRA_KEYS,
    BuildingOutline,
    PortExtra,
    toml_point,
    toml_string,
)

from stridefix_analyzer.schemes import NAMES as SCHEME_NAMES

#: Context kinds and absolute methods by their names in the file (site_t.CONTEXT_*, fix_t.METHOD_*).
CONTEXT_KIND_NAMES = ("outdoor", "building", "floor")
METHOD_NAMES = ("wifi", "ble", "gnss")
#: The fusion schemes a context may use (every pose_t scheme but the controller itself).
FUSION_SCHEMES = tuple(SCHEME_NAMES[: pose_t.SCHEME_CONTROLLER])


@dataclasses.dataclass
class ContextSpec:
    """Optional overrides of one derived context (the build derives every context)."""

    kind: str  # "outdoor" | "building" | "floor"
    building: str | None = None  # for building / floor
    floor: int | None = None  # for floor
    scheme: str | None = None  # a fusion scheme name (schemes.py), None: the build's default
    method: str | None = None  # "wifi" | "ble" | "gnss", None: the build's default


def _xy(path: str, entry: str, key: str, p: Any, error: type[ValueError]) -> tuple[float, float]:
    ok = isinstance(p, list) and len(p) == 2
    ok = ok and all(isinstance(c, int | float) and not isinstance(c, bool) and math.isfinite(c) for c in p)
    if not ok:
        raise error(f"{path}: {entry}: {key}: {p!r} is not [x, y] of finite numbers")
    return float(p[0]), float(p[1])


def _floor_list(path: str, entry: str, v: Any, error: type[ValueError]) -> list[int]:
    if not (isinstance(v, list) and v and all(isinstance(f, int) and not isinstance(f, bool) for f in v)):
        raise error(f"{path}: {entry}: floors: {v!r} is not a list of floor indices")
    if len(set(v)) != len(v):
        raise error(f"{path}: {entry}: floors: {v} names a floor twice")
    return sorted(v)


def _buildings(path: str, doc: dict[str, Any], error: type[ValueError]) -> list[BuildingOutline]:
    out: list[BuildingOutline] = []
    for i, b in enumerate(doc.get("building", [])):
        entry = f"[[building]] {i + 1}"
        extra = sorted(set(b) - {"name", "outline", "floors"})
        if extra:
            raise error(f"{path}: {entry}: {extra[0]}: unknown field (known: floors, name, outline)")
        name = b.get("name")
        if not (isinstance(name, str) and name):
            raise error(f"{path}: {entry}: name: {name!r} is not a non-empty string")
        if any(o.name == name for o in out):
            raise error(f"{path}: {entry}: name: {name!r} already given")
        pts = b.get("outline")
        if not (isinstance(pts, list) and len(pts) >= 3):
            raise error(f"{path}: {entry}: outline: needs a list of at least three [x, y] vertices")
        outline = [_xy(path, entry, f"outline[{k}]", p, error) for k, p in enumerate(pts)]
        out.append(BuildingOutline(name, outline, _floor_list(path, entry, b.get("floors"), error)))
    return out


def parse_port_extra(
    path: str, entry: str, p: dict[str, Any], kind: str, error: type[ValueError]
) -> PortExtra | None:
    """The extras of one ``[[port]]`` table (None when it has none); links are resolved later."""
    if not set(p) & PORT_EXTRA_KEYS:
        return None
    e = PortExtra()
    name = p.get("name", "")
    if not isinstance(name, str):
        raise error(f"{path}: {entry}: name: {name!r} is not a string")
    e.name = name
    b = p.get("building")
    if b is not None and not (isinstance(b, str) and b):
        raise error(f"{path}: {entry}: building: {b!r} is not a building name")
    e.building = b
    out = p.get("outdoor", False)
    if not isinstance(out, bool):
        raise error(f"{path}: {entry}: outdoor: {out!r} is not true or false")
    e.outdoor = out
    steps = p.get("steps", 0)
    if isinstance(steps, bool) or not isinstance(steps, int) or not 0 <= steps <= 32767:
        raise error(f"{path}: {entry}: steps: {steps!r} is not a step count 0..32767")
    if kind != "stairs" and steps != 0:
        raise error(f"{path}: {entry}: steps: only stairs have steps, a {kind} has {steps}")
    e.steps = steps
    if "ends" in p:
        ends = p["ends"]
        if kind != "stairs":
            raise error(f"{path}: {entry}: ends: only stairs have endpoints")
        if not (isinstance(ends, list) and len(ends) == 2):
            raise error(f"{path}: {entry}: ends: {ends!r} is not [[x, y] lowest floor, [x, y] highest floor]")
        e.end_lo = _xy(path, entry, "ends[0]", ends[0], error)
        e.end_hi = _xy(path, entry, "ends[1]", ends[1], error)
    links = p.get("links", [])
    if not (isinstance(links, list) and all(isinstance(n, str) and n for n in links)):
        raise error(f"{path}: {entry}: links: {links!r} is not a list of port names")
    e.links = list(links)
    return e


def _check_port_extras(
    path: str,
    extras: list[PortExtra],
    kinds: list[str],
    buildings: list[BuildingOutline],
    error: type[ValueError],
) -> None:
    names = {b.name for b in buildings}
    seen: dict[str, int] = {}
    for i, e in enumerate(extras):
        entry = f"[[port]] {i + 1}"
        if e.name:
            if e.name in seen:
                raise error(f"{path}: {entry}: name: {e.name!r} already given in [[port]] {seen[e.name]}")
            seen[e.name] = i + 1
        if e.building is not None and e.building not in names:
            raise error(f"{path}: {entry}: building: {e.building!r} is not a [[building]] name")
        if buildings and kinds[i] == "stairs" and e.steps == 0:
            raise error(f"{path}: {entry}: steps: stairs need their step count (> 0) for the context map")
    for i, e in enumerate(extras):
        for n in e.links:
            if n not in seen:
                raise error(f"{path}: [[port]] {i + 1}: links: {n!r} is not a [[port]] name")
            if n == e.name:
                raise error(f"{path}: [[port]] {i + 1}: links: a port is its own neighbour without a link")


def _contexts(
    path: str, doc: dict[str, Any], buildings: list[BuildingOutline], error: type[ValueError]
) -> list[ContextSpec]:
    by_name = {b.name: b for b in buildings}
    out: list[ContextSpec] = []
    for i, c in enumerate(doc.get("context", [])):
        entry = f"[[context]] {i + 1}"
        extra = sorted(set(c) - {"kind", "building", "floor", "scheme", "method"})
        if extra:
            raise error(
                f"{path}: {entry}: {extra[0]}: unknown field (known: building, floor, kind, method, scheme)"
            )
        kind = c.get("kind")
        if kind not in CONTEXT_KIND_NAMES:
            raise error(f"{path}: {entry}: kind: {kind!r} is not one of {', '.join(CONTEXT_KIND_NAMES)}")
        spec = ContextSpec(kind)
        if kind == "outdoor":
            for k in ("building", "floor"):
                if k in c:
                    raise error(f"{path}: {entry}: {k}: the outdoor context has no {k}")
        else:
            b = c.get("building")
            if b not in by_name:
                raise error(f"{path}: {entry}: building: {b!r} is not a [[building]] name")
            spec.building = b
        if kind == "floor":
            f = c.get("floor")
            if isinstance(f, bool) or not isinstance(f, int) or f not in by_name[str(spec.building)].floors:
                raise error(f"{path}: {entry}: floor: {f!r} is not one of building {spec.building}'s floors")
            spec.floor = f
        elif kind == "building" and "floor" in c:
            raise error(f"{path}: {entry}: floor: a building context has no floor")
        scheme = c.get("scheme")
        if scheme is not None and scheme not in FUSION_SCHEMES:
            raise error(
                f"{path}: {entry}: scheme: {scheme!r} is not a fusion scheme ({', '.join(FUSION_SCHEMES)})"
            )
        method = c.get("method")
        if method is not None and method not in METHOD_NAMES:
            raise error(f"{path}: {entry}: method: {method!r} is not one of {', '.join(METHOD_NAMES)}")
        spec.scheme, spec.method = scheme, method
        if any((o.kind, o.building, o.floor) == (spec.kind, spec.building, spec.floor) for o in out):
            raise error(f"{path}: {entry}: kind: this context is already given")
        out.append(spec)
    return out


def parse_context_tables(
    path: str,
    doc: dict[str, Any],
    port_extras: list[PortExtra | None],
    port_kinds: list[str],
    error: type[ValueError],
) -> tuple[list[BuildingOutline], list[PortExtra], list[ContextSpec]]:
    """``[[building]]``, the ports' extras (``port_extras``: :func:`parse_port_extra` per port, in
    order) and ``[[context]]`` of a parsed TOML document; extras are [] when no port has any, else
    one per port (defaults for ports without)."""
    buildings = _buildings(path, doc, error)
    extras = [e or PortExtra() for e in port_extras] if any(e is not None for e in port_extras) else []
    if buildings and not extras:
        extras = [PortExtra() for _ in port_extras]
    _check_port_extras(path, extras, port_kinds, buildings, error)
    return buildings, extras, _contexts(path, doc, buildings, error)


def context_tables_toml(buildings: list[BuildingOutline], contexts: list[ContextSpec]) -> list[str]:
    """The ``[[building]]`` and ``[[context]]`` lines (port extras: :func:`port_extra_lines`)."""
    out: list[str] = []
    for b in buildings:
        out += ["", "[[building]]", f"name = {toml_string(b.name)}"]
        out.append("outline = [" + ", ".join(toml_point(p) for p in b.outline) + "]")
        out.append("floors = [" + ", ".join(str(f) for f in b.floors) + "]")
    for c in contexts:
        out += ["", "[[context]]", f'kind = "{c.kind}"']
        if c.building is not None:
            out.append(f"building = {toml_string(c.building)}")
        if c.floor is not None:
            out.append(f"floor = {c.floor}")
        if c.scheme is not None:
            out.append(f'scheme = "{c.scheme}"')
        if c.method is not None:
            out.append(f'method = "{c.method}"')
    return out
