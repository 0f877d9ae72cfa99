"""The truth of a walk's positioning contexts and of its transitions between them (what ``stridefix
bench controller`` scores the controller against; Jäger, Süß, Becker §III-B/C), for a world with
building outlines (world_parts.py).

Contexts (``contexts``): the outdoor context (kind ``outdoor``, no building, the lowest floor of the
doors to the outside) when the world has such a door, then one ``floor`` context per (building, floor),
buildings in the world's order — the contexts the site build derives (docs/building.md). The walker is
in the outdoor context outside every outline, else in (its building, its true floor).

Transitions (``transitions``), in time order, each with the port it used (the building description's
port name, building.py), the context before and after it and its truth time:

* door: the walker sample at which the outline membership changed (the first sample on the new side:
  it crossed the outline between the sample before and this one);
* stairs: the time the walker stepped off the last stair onto the new floor (its distance walked
  reached the end of the staircase's last flight, interpolated between samples); the context before is
  the one where the first flight began;
* elevator: the time the cab stopped on the new floor and its doors opened (the end of the ride).

Times are seconds since the simulation start (``t_s``) and the truth log's unwrapped board time in µs
(``t_us``). Cost O(samples).
"""

from __future__ import annotations

import numpy as np

from .building import port_rows
from .walker import Walk
from .world import World


def contexts(world: World) -> list[dict]:
    """The world's contexts as dicts (kind, building, floor), in the order described above."""
    out = []
    doors = [d.floor for d in world.doors]
    if doors:
        out.append({"kind": "outdoor", "building": None, "floor": min(doors)})
    for o in world.outlines:
        out += [{"kind": "floor", "building": o.name, "floor": int(f)} for f in o.floors]
    return out


def context_track(world: World, walk: Walk) -> np.ndarray:
    """(n,) index into :func:`contexts` of the context the walker is in at each sample."""
    ctx = contexts(world)
    index = {(c["building"], c["floor"]): i for i, c in enumerate(ctx) if c["kind"] == "floor"}
    out = np.zeros(len(walk.t_s), np.int64)  # outdoors: the outdoor context (index 0)
    for o in world.outlines:
        m = o.holds(walk.x_m, walk.y_m)
        for f in o.floors:
            out[m & (walk.floor == f)] = index[(o.name, int(f))]
    return out


def _t_at_s(walk: Walk, s_m: float) -> float:
    """When the distance walked first reaches ``s_m`` (interpolated between samples) [s]."""
    i = int(np.searchsorted(walk.s_m, s_m - 1e-9, side="left"))
    if i <= 0:
        return float(walk.t_s[0])
    i = min(i, len(walk.s_m) - 1)
    ds = float(walk.s_m[i] - walk.s_m[i - 1])
    f = (s_m - float(walk.s_m[i - 1])) / ds if ds > 0 else 1.0
    return float(walk.t_s[i - 1] + min(max(f, 0.0), 1.0) * (walk.t_s[i] - walk.t_s[i - 1]))


def _staircases(walk: Walk) -> list[tuple[float, float]]:
    """(s at the first flight's start, s at the last flight's end) of each staircase the route climbs."""
    zones = walk.route.gait_zones
    out = []
    for a, b, mode in zones:
        if mode != "slow":
            continue
        fl = [(fa, fb) for fa, fb, m in zones if m == "stairs" and a <= fa and fb <= b]
        if fl:
            out.append((min(f[0] for f in fl), max(f[1] for f in fl)))
    return out


def transitions(world: World, walk: Walk, start_us: int) -> list[dict]:
    """The walk's transitions (see the module docstring) as dicts."""
    if not world.outlines:
        return []
    ctx = contexts(world)
    track = context_track(world, walk)
    ports = port_rows(world)
    end_t = float(walk.t_s[-1])

    def port_of(kind: str, x: float, y: float) -> str:
        cand = [p for p in ports if p[0] == kind]
        return min(cand, key=lambda p: np.hypot(p[1] - x, p[2] - y))[5].name if cand else ""

    def at(t_s: float) -> int:
        return int(min(int(round(t_s / (walk.t_s[1] - walk.t_s[0]))), len(track) - 1))

    rows = []
    which = np.full(len(walk.t_s), -1)  # the outline the walker is in (the first that holds it)
    for k in range(len(world.outlines) - 1, -1, -1):
        which[world.outlines[k].holds(walk.x_m, walk.y_m)] = k
    for i in np.flatnonzero(which[1:] != which[:-1]) + 1:
        x, y = float(walk.x_m[i]), float(walk.y_m[i])
        rows.append(("door", port_of("door", x, y), int(track[i - 1]), int(track[i]), float(walk.t_s[i])))
    for s_a, s_b in _staircases(walk):
        t_a, t_b = _t_at_s(walk, s_a), _t_at_s(walk, s_b)
        if t_b >= end_t:
            continue
        x, y = float(walk.x_m[at(t_b)]), float(walk.y_m[at(t_b)])
        rows.append(("stairs", port_of("stairs", x, y), int(track[at(t_a)]), int(track[at(t_b)]), t_b))
    for ts, te, _dz, _i in walk.rides:
        if te >= end_t:
            continue
        k = at(ts)
        rows.append(
            ("elevator", port_of("elevator", walk.x_m[k], walk.y_m[k]), int(track[k]), int(track[at(te)]), te)
        )
    rows.sort(key=lambda r: r[4])
    out = []
    for kind, port, a, b, t in rows:
        out.append(
            {
                "kind": kind,
                "port": port,
                "from": a,
                "to": b,
                "from_context": ctx[a],
                "to_context": ctx[b],
                "t_s": round(t, 6),
                "t_us": start_us + int(round(t * 1e6)),
            }
        )
    return out
