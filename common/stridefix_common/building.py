"""The building description's schema (``building.toml``, docs/building.md), the part the simulator
writes and the analyzer reads: the format line, the port kinds, a building's outline and a port's
context-map extras, and the TOML lines of those extras. The parser and its checks are the
analyzer's (:mod:`stridefix_analyzer.radiomap.building`); the simulator writes a world's description
(:mod:`stridefix_sim.building`) with these types, so both sides share one spelling of each field.
"""

from __future__ import annotations

import dataclasses
import json

#: the first line's value: ``format = "stridefix-building 1"``
FORMAT = "stridefix-building 1"
#: ``[[port]] kind`` names and their codes in the site file (site_t's port kinds)
PORT_KIND_CODES = {"door": 1, "stairs": 2, "elevator": 3}
#: the context-map keys a ``[[port]]`` may carry beside kind, position, radius and floors
PORT_EXTRA_KEYS = {"name", "building", "outdoor", "steps", "ends", "links"}


@dataclasses.dataclass
class BuildingOutline:
    """A building: unique name, outline polygon (map frame [m], ≥ 3 vertices, closed implicitly) and
    its floor indices."""

    name: str
    outline: list[tuple[float, float]]
    floors: list[int]


@dataclasses.dataclass
class PortExtra:
    """The controller's extras of one ``Building.ports`` row (same order)."""

    name: str = ""  # unique when given; links refer to it
    building: str | None = None  # BuildingOutline.name, None: an outdoor port
    outdoor: bool = False  # leads outdoors (a door with an outdoor neighbour)
    steps: int = 0  # stairs: steps end to end (> 0); others 0
    end_lo: tuple[float, float] | None = None  # stairs: endpoint on the lowest floor (None: centre)
    end_hi: tuple[float, float] | None = None  # stairs: endpoint on the highest floor
    links: list[str] = dataclasses.field(default_factory=list)  # names of reachable ports


def toml_point(p: tuple[float, float]) -> str:
    return f"[{p[0]!r}, {p[1]!r}]"


def toml_string(v: str) -> str:
    return json.dumps(v, ensure_ascii=False)  # a TOML basic string


def port_extra_lines(e: PortExtra, centre: tuple[float, float]) -> list[str]:
    """The ``[[port]]`` lines of one port's extras (``outdoor`` always, so the extras round-trip; a
    missing stairs endpoint beside a given one is written as the port's ``centre``)."""
    out = [f"name = {toml_string(e.name)}"] if e.name else []
    if e.building is not None:
        out.append(f"building = {toml_string(e.building)}")
    out.append(f"outdoor = {'true' if e.outdoor else 'false'}")
    if e.steps:
        out.append(f"steps = {e.steps}")
    if e.end_lo is not None or e.end_hi is not None:
        out.append(f"ends = [{toml_point(e.end_lo or centre)}, {toml_point(e.end_hi or centre)}]")
    if e.links:
        out.append("links = [" + ", ".join(toml_string(n) for n in e.links) + "]")
    return out
