"""The positioning context map of a site (site file v3; Jäger, Süß, Becker §III-B/C): buildings with
outlines, the ports' extras and links, the contexts with their localization scheme descriptor (LSD:
scheme + the absolute method it fuses) and context determination descriptor (CDD: the method that
recognises the context and its constellation of floor-identifying APs or beacons).

:func:`build_context_map` derives it from a building description (``[[building]]`` entries,
docs/building.md) and the site's survey; :func:`single_building_context_map` makes one for a
one-building site without a description (the real data sets). Derivation (building_spec.md):

* one outdoor context when any port leads outdoors: method GNSS, CDD GNSS (no members: a fix
  identifies it), its floor the lowest floor of the outdoor doors;
* one floor context per (building, floor); its method ``ble`` when the site has beacons on that floor
  inside the building's outline, else ``wifi``; the CDD method is the LSD method; a building context
  only where a ``[[context]]`` asks for one (floor: the building's lowest);
* the scheme: ``particle`` (:data:`MAPPED_SCHEME`) for a floor context whose floor has walls inside
  the building's outline (the map-aware scheme: walls kill the particles that cross them; where there
  is no plan it has nothing the others lack and costs ten times more), else ``kalman``
  (:data:`DEFAULT_SCHEME`: outdoors, unmapped floors, building contexts), unless a ``[[context]]``
  overrides scheme or method;
* the constellation of a context with RPs (the RPs on floor f inside b's outline; every RP of floor
  f when the site has one building): an AP or beacon is a member when its loudest mean RSSI at the
  context's RPs exceeds its loudest mean RSSI at every other RP by :data:`CDD_MARGIN_DB` (or no other
  RP hears it) — a floor-identifying RSSI range (§III-B); its ``cdd_min_dbm`` = max(loudest
  elsewhere + :data:`CDD_ABOVE_ELSEWHERE_DB`, the median of its mean RSSIs at the context's RPs).
  BLE floors use the survey's BLE readings, each at its nearest RP of its floor, when the build has
  readings on that floor, and then the threshold is also at least :data:`CDD_ABOVE_ELSEWHERE_DB`
  above the loudest single reading of the beacon at any other RP (a live scan is single readings,
  which pass a threshold set on means: a beacon heard across a slab, a stairwell or an atrium at
  −64 dBm must not name its own floor there), and a beacon whose own loudest reading does not reach
  that threshold is no member (it names no floor anywhere); only a beacon installed on the floor
  (inside the outline) is its member: a survey that never reached a floor hears that floor's beacons
  loudest elsewhere, and that names the wrong floor; else the beacons of the floor inside the
  outline are members at the path-loss model's RSSI at :data:`BLE_MODEL_RANGE_M`;
* ``cdd_min_hits`` = :data:`CDD_HITS_MANY` when the context has at least :data:`CDD_MANY_MEMBERS`
  members, else 1. A context without members cannot be identified by the CLS: the summary says so.

Cost: O(E log E) for E radio-map entries (plus R log R for R BLE readings), O(P·V) point-in-polygon
tests for P RPs and V outline vertices.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from stridefix import fix_t, site_t

from stridefix_analyzer.io.site_v3 import CONTEXT_KINDS, CONTEXT_METHODS
from stridefix_analyzer.io.sitefile import set_counts
from stridefix_analyzer.radiomap.building_contexts import PortExtra
from stridefix_analyzer.schemes import scheme_code, scheme_name

#: An AP's (beacon's) loudest mean RSSI at a context's RPs must exceed its loudest elsewhere by this
#: [dB] to identify the context: the difference of two loudest means, each off by an AP's shadowing
#: σ ≈ 4–6 dB at a few points, is not a floor difference below about one σ√2 ≈ 6 dB.
CDD_MARGIN_DB = 6.0
#: A member's threshold sits this far above the loudest RSSI heard anywhere else [dB]: half the
#: margin, so a reading at the threshold is still 3 dB (about half a σ) clear of any other context.
CDD_ABOVE_ELSEWHERE_DB = 3.0
#: Without survey BLE readings a beacon identifies its floor when heard as loud as the path-loss
#: model gives at this range [m]: within a room or corridor of it, not through a floor slab
#: (a slab costs ~15–20 dB, the model at 5 m is 14 dB (n = 2) above 25 m).
BLE_MODEL_RANGE_M = 5.0
#: With this many members or more, a context needs CDD_HITS_MANY of them heard: one member alone can
#: be a reflection or a door left open (σ ≈ 4–6 dB); two independent ones rarely are.
CDD_MANY_MEMBERS = 4
CDD_HITS_MANY = 2
#: The outline of a site without a building description: the RPs' convex hull grown by this [m]
#: (a walker reaches past the outermost surveyed point by about a corridor's width).
OUTLINE_MARGIN_M = 5.0
#: A staircase's step count without one given: its height / this riser height [m] (building codes
#: allow 0.15–0.19 m, 0.17 m the common one).
STAIR_RISER_M = 0.17
#: The scheme of every context without walls: measured, every scheme from its first fix, leave one
#: walk out (realbench fusion), kalman is the best fused scheme or within 0.5 % of it on ipin2023 (25
#: hand-held trials; mean 4.2 m against ekf 6.3, adaptive 6.7), gsd and msindoor site1/F2, and on
#: other walkers' trials of the ipin2023 routes; the ekf, which learns heading bias and stride scale,
#: loses up to half of its accuracy when a hand-held phone's device-to-walk angle changes.
DEFAULT_SCHEME = "kalman"
#: the scheme of a floor context with walls (see the module text)
MAPPED_SCHEME = "particle"
_METHOD_IDS = {name: code for code, name in CONTEXT_METHODS.items()}


class ContextMapError(ValueError):
    """The building description and the site do not make a context map (names the part)."""


@dataclasses.dataclass
class _Context:
    kind: int
    building: int  # index, −1: outdoor
    floor: int
    scheme: int
    method: int
    rps: np.ndarray  # bool per RP: the context's RPs
    beacons: np.ndarray  # bool per site beacon: those inside it (model-based BLE constellations)


def inside(x: np.ndarray, y: np.ndarray, polygon: list[tuple[float, float]]) -> np.ndarray:
    """Points strictly inside ``polygon`` (even-odd ray casting; vertices in order, closed
    implicitly); bool array of ``x``'s shape."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    out = np.zeros(x.shape, bool)
    n = len(polygon)
    for k in range(n):
        (x0, y0), (x1, y1) = polygon[k], polygon[(k + 1) % n]
        if y0 == y1:
            continue
        crosses = (y0 > y) != (y1 > y)
        xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        out ^= crosses & (x < xc)
    return out


def _members(ids: np.ndarray, rps: np.ndarray, means: np.ndarray, own: np.ndarray) -> list[tuple[int, float]]:
    """(id, cdd_min_dbm) of the members among per-(id, RP) mean RSSIs for a context whose RPs are
    ``own`` (bool per RP): the rules of the module docstring, for every id at once. Per id: its
    loudest level at the context's RPs against its loudest elsewhere, then the median of its levels
    there (the middle one, or the mean of the two middle ones; NaN with a NaN, as ``np.median``) or
    a margin above elsewhere, whichever is higher (Python's ``max`` of the two, in that order)."""
    mine = own[rps]
    if not mine.any():
        return []
    uniq, group = np.unique(ids, return_inverse=True)
    group = group.reshape(-1)
    n = len(uniq)
    loud = np.full(n, -np.inf)
    np.maximum.at(loud, group[mine], means[mine])
    has_else = np.bincount(group[~mine], minlength=n) > 0
    else_max = np.full(n, -np.inf)
    np.maximum.at(else_max, group[~mine], means[~mine])
    g, v = group[mine], means[mine]
    order = np.lexsort((v, g))  # each id's levels at its own RPs, ascending (NaN last)
    g, v = g[order], v[order]
    count = np.bincount(g, minlength=n)
    start = np.cumsum(count) - count
    has_own = count > 0
    h = np.where(has_own, count // 2, 0)
    hi = v[np.minimum(start + h, len(v) - 1)]
    lo = v[np.minimum(start + np.maximum(h - 1, 0), len(v) - 1)]
    median = np.where(count % 2 == 1, hi, (lo + hi) / 2)
    median = np.where(np.isnan(v[np.minimum(start + count - 1, len(v) - 1)]), np.nan, median)
    with np.errstate(invalid="ignore"):
        member = has_own & ~(has_else & ~(loud >= else_max + CDD_MARGIN_DB))
        above = else_max + CDD_ABOVE_ELSEWHERE_DB
        floor_dbm = np.where(has_else, np.where(median > above, median, above), median)
    return [(int(uniq[k]), float(floor_dbm[k])) for k in np.flatnonzero(member)]


def _ble_means(
    site: site_t, placed: dict[str, np.ndarray]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each placed BLE reading at its nearest RP of its floor; (beacon, RP, mean RSSI, loudest single
    RSSI) per (beacon, RP)."""
    from scipy.spatial import cKDTree

    rp_x, rp_y, rp_floor = (np.asarray(v) for v in (site.rp_x_m, site.rp_y_m, site.rp_floor))
    ids, rps, rssi = [], [], []
    for f in np.unique(placed["floor"]):
        on = np.flatnonzero(rp_floor == f)
        sel = placed["floor"] == f
        if not on.size or not sel.any():
            continue
        _, k = cKDTree(np.column_stack([rp_x[on], rp_y[on]])).query(
            np.column_stack([placed["x_m"][sel], placed["y_m"][sel]])
        )
        ids.append(placed["beacon_id"][sel])
        rps.append(on[k])
        rssi.append(placed["rssi_dbm"][sel])
    if not ids:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
    keys, inv = np.unique(
        np.column_stack([np.concatenate(ids), np.concatenate(rps)]), axis=0, return_inverse=True
    )
    inv = inv.reshape(-1)
    levels = np.concatenate(rssi)
    means = np.bincount(inv, weights=levels) / np.bincount(inv)
    loudest = np.full(len(keys), -np.inf)
    np.maximum.at(loudest, inv, levels)
    return keys[:, 0].astype(np.int64), keys[:, 1].astype(np.int64), means, loudest


def _ble_members(
    site: site_t, c: _Context, ble: tuple[np.ndarray, ...] | None
) -> tuple[list[tuple[int, float]], str]:
    """(id, cdd_min_dbm) of a BLE floor context's members and where they come from (the module
    text): the beacons installed on the floor; each heard at the context's RPs by the survey's rule
    (:func:`_members`; one heard there but not louder than elsewhere names no floor), one not heard
    there at the path-loss model's RSSI at :data:`BLE_MODEL_RANGE_M`; either threshold raised to
    :data:`CDD_ABOVE_ELSEWHERE_DB` above its loudest single reading elsewhere, and a beacon whose own
    loudest reading stays below that dropped."""
    model = {int(site.beacon_id[i]): _model_dbm(site, int(i)) for i in np.flatnonzero(c.beacons)}
    if ble is None:
        return sorted(model.items()), f"ble model at {BLE_MODEL_RANGE_M:g} m"
    ids, rps, means, loudest = ble
    mine = c.rps[rps]
    by_survey = dict(_members(ids, rps, means, c.rps))
    out: list[tuple[int, float]] = []
    from_model = 0
    for ident, dbm in model.items():
        of = ids == ident
        heard_here = bool(np.any(of & mine))
        if heard_here and ident not in by_survey:
            continue
        from_model += not heard_here
        level = max(
            by_survey.get(ident, dbm),
            float(loudest[of & ~mine].max(initial=-np.inf)) + CDD_ABOVE_ELSEWHERE_DB,
        )
        if not heard_here or float(loudest[of & mine].max()) >= level:
            out.append((ident, level))
    source = "ble readings" + (
        f", {from_model} by the model at {BLE_MODEL_RANGE_M:g} m" if from_model else ""
    )
    return sorted(out), source


def _model_dbm(site: site_t, i: int) -> float:
    own = site.beacon_rssi_1m_dbm[i]
    r1 = own if math.isfinite(own) else site.ble_rssi_1m_dbm
    return float(r1 - 10.0 * site.ble_path_loss_exponent * math.log10(BLE_MODEL_RANGE_M))


def _write(
    site: site_t,
    names: list[str],
    outlines: list[list[tuple[float, float]]],
    contexts: list[_Context],
    ble_placed: dict[str, np.ndarray] | None,
) -> dict[str, Any]:
    """Buildings, contexts and constellations into ``site``; returns the summary."""
    site.building_name = list(names)
    site.outline_x_m = [float(p[0]) for o in outlines for p in o]
    site.outline_y_m = [float(p[1]) for o in outlines for p in o]
    site.outline_building = [b for b, o in enumerate(outlines) for _ in o]
    wifi = (
        np.asarray(site.ap_bssid, np.int64)[np.asarray(site.entry_ap, np.int64)]
        if site.n_entries
        else np.zeros(0, np.int64),
        np.asarray(site.entry_rp, np.int64),
        np.asarray(site.entry_mean_dbm, float),
    )
    ble = _ble_means(site, ble_placed) if ble_placed is not None and len(ble_placed["rssi_dbm"]) else None
    rows: list[tuple[int, int, float]] = []
    hits: list[int] = []
    summary: list[dict[str, Any]] = []
    for c_index, c in enumerate(contexts):
        source = "gnss"
        members: list[tuple[int, float]] = []
        if c.method == fix_t.METHOD_WIFI:
            members, source = _members(*wifi, c.rps), "survey"
        elif c.method == fix_t.METHOD_BLE:
            members, source = _ble_members(site, c, ble)
        members.sort()
        rows += [(c_index, ident, dbm) for ident, dbm in members]
        hits.append(CDD_HITS_MANY if len(members) >= CDD_MANY_MEMBERS else 1)
        summary.append(
            {
                "kind": CONTEXT_KINDS[c.kind],
                "building": names[c.building] if c.building >= 0 else None,
                "floor": c.floor,
                "scheme": scheme_name(c.scheme),
                "method": CONTEXT_METHODS[c.method],
                "cdd_method": CONTEXT_METHODS[c.method],
                "members": len(members),
                "min_hits": hits[-1],
                "rps": int(c.rps.sum()),
                "cdd_from": source,
                "identifiable": bool(members) or c.method == fix_t.METHOD_GNSS,
            }
        )
    site.context_kind = [c.kind for c in contexts]
    site.context_building = [c.building for c in contexts]
    site.context_floor = [c.floor for c in contexts]
    site.context_scheme = [c.scheme for c in contexts]
    site.context_method = [c.method for c in contexts]
    site.context_cdd_method = [c.method for c in contexts]
    site.context_cdd_min_hits = hits
    site.cdd_context = [r[0] for r in rows]
    site.cdd_id = [r[1] for r in rows]
    site.cdd_min_dbm = [r[2] for r in rows]
    set_counts(site)
    return {"contexts": summary, "buildings": list(names), "n_links": site.n_links, "n_cdd": site.n_cdd}


def _stair_steps(site: site_t, i: int) -> int:
    lo, hi = site.port_floor_lo[i] - site.lowest_floor, site.port_floor_hi[i] - site.lowest_floor
    return max(1, round((site.floor_height_m[hi] - site.floor_height_m[lo]) / STAIR_RISER_M))


def build_context_map(
    site: site_t, building: Any, ble_placed: dict[str, np.ndarray] | None = None
) -> dict[str, Any]:
    """The context map of ``building`` (a :class:`~.building.Building` with ``buildings``, merged into
    ``site`` first: its ports are the site's) written into ``site``; ``ble_placed``: the build's BLE
    readings on the truth (:func:`~.beacons.place_readings`), None without. Returns the summary.

    Raises
    ------
    ContextMapError
        A building floor outside the site's floors, or port rows that are not the description's.
    """
    lowest, top = site.lowest_floor, site.lowest_floor + site.n_floors - 1
    bs = building.buildings
    index = {b.name: k for k, b in enumerate(bs)}
    for b in bs:
        bad = [f for f in b.floors if not lowest <= f <= top]
        if bad:
            raise ContextMapError(
                f"building {b.name}: floor {bad[0]} outside the site's floors {lowest}..{top}"
            )
    if len(building.ports) != site.n_ports:
        raise ContextMapError(f"the description has {len(building.ports)} ports, the site {site.n_ports}")
    extras = building.port_extras or [PortExtra() for _ in building.ports]
    site.port_building = [index[e.building] if e.building is not None else -1 for e in extras]
    site.port_outdoor = [int(e.outdoor) for e in extras]
    site.port_steps = [e.steps for e in extras]
    centre = list(zip(site.port_x_m, site.port_y_m))
    lo_xy = [e.end_lo or centre[i] for i, e in enumerate(extras)]
    hi_xy = [e.end_hi or centre[i] for i, e in enumerate(extras)]
    site.port_lo_x_m, site.port_lo_y_m = [p[0] for p in lo_xy], [p[1] for p in lo_xy]
    site.port_hi_x_m, site.port_hi_y_m = [p[0] for p in hi_xy], [p[1] for p in hi_xy]
    by_name = {e.name: i for i, e in enumerate(extras) if e.name}
    pairs = sorted({tuple(sorted((i, by_name[n]))) for i, e in enumerate(extras) for n in e.links})
    site.link_a, site.link_b = [p[0] for p in pairs], [p[1] for p in pairs]
    overrides = {(c.kind, c.building, c.floor): c for c in building.contexts}
    rp_x, rp_y, rp_floor = (np.asarray(v) for v in (site.rp_x_m, site.rp_y_m, site.rp_floor))
    bx, by, bfl = (np.asarray(v, float) for v in (site.beacon_x_m, site.beacon_y_m, site.beacon_floor))

    def lsd(
        key: tuple[str, str | None, int | None], method: str, default: str = DEFAULT_SCHEME
    ) -> tuple[int, int]:
        o = overrides.get(key)
        return scheme_code((o and o.scheme) or default), _METHOD_IDS[(o and o.method) or method]

    wall_mid_x = (np.asarray(site.wall_x0_m, float) + np.asarray(site.wall_x1_m, float)) / 2
    wall_mid_y = (np.asarray(site.wall_y0_m, float) + np.asarray(site.wall_y1_m, float)) / 2
    wall_floor = np.asarray(site.wall_floor, int)

    contexts: list[_Context] = []
    outdoor = [i for i, e in enumerate(extras) if e.outdoor]
    if outdoor:
        scheme, method = lsd(("outdoor", None, None), "gnss")
        floor = min(site.port_floor_lo[i] for i in outdoor)
        none_rp, none_b = np.zeros(site.n_rp, bool), np.zeros(site.n_beacons, bool)
        contexts.append(_Context(site_t.CONTEXT_OUTDOOR, -1, floor, scheme, method, none_rp, none_b))
    for k, b in enumerate(bs):
        in_rp = inside(rp_x, rp_y, b.outline) if len(bs) > 1 else np.ones(site.n_rp, bool)
        in_b = inside(bx, by, b.outline) if len(bs) > 1 else np.ones(site.n_beacons, bool)
        if ("building", b.name, None) in overrides:
            scheme, method = lsd(("building", b.name, None), "wifi")
            on = np.isin(rp_floor, b.floors)
            contexts.append(
                _Context(
                    site_t.CONTEXT_BUILDING,
                    k,
                    min(b.floors),
                    scheme,
                    method,
                    in_rp & on,
                    in_b & np.isin(bfl, b.floors),
                )
            )
        in_w = inside(wall_mid_x, wall_mid_y, b.outline) if len(bs) > 1 else np.ones(site.n_walls, bool)
        for f in b.floors:
            has_ble = bool(np.any(in_b & (bfl == f)))
            mapped = bool(np.any(in_w & (wall_floor == f)))
            scheme, method = lsd(
                ("floor", b.name, f),
                "ble" if has_ble else "wifi",
                MAPPED_SCHEME if mapped else DEFAULT_SCHEME,
            )
            contexts.append(
                _Context(
                    site_t.CONTEXT_FLOOR, k, f, scheme, method, in_rp & (rp_floor == f), in_b & (bfl == f)
                )
            )
    return _write(site, [b.name for b in bs], [b.outline for b in bs], contexts, ble_placed)


def hull_outline(
    x: np.ndarray, y: np.ndarray, margin_m: float = OUTLINE_MARGIN_M
) -> list[tuple[float, float]]:
    """The convex hull of the points grown by ``margin_m`` [m]: the hull of 16 points on a circle of
    ``margin_m / cos(π/16)`` about each point (every point of the grown hull is within it)."""
    from scipy.spatial import ConvexHull

    pts = np.unique(np.column_stack([x, y]).astype(float), axis=0)
    if not len(pts):
        raise ContextMapError("the site has no reference points to draw an outline about")
    a = np.arange(16) * (2 * math.pi / 16)
    r = margin_m / math.cos(math.pi / 16)
    ring = (pts[:, None, :] + r * np.stack([np.cos(a), np.sin(a)], axis=1)[None]).reshape(-1, 2)
    hull = ConvexHull(ring)
    return [(float(ring[v, 0]), float(ring[v, 1])) for v in hull.vertices]


def single_building_context_map(
    site: site_t, scheme: str = DEFAULT_SCHEME, ble_placed: dict[str, np.ndarray] | None = None
) -> site_t:
    """A context map for a one-building site without a description, written into ``site`` (returned):
    one building (outline :func:`hull_outline` of every RP), one floor context per site floor with
    the LSD ``scheme`` and method ``ble`` where the site has beacons on the floor, else ``wifi``; CDD by
    the module's rules (BLE from ``ble_placed``, the build's placed readings, when given); no outdoor
    context. Existing ports belong to the building; a staircase without a step count gets height /
    :data:`STAIR_RISER_M`."""
    outline = hull_outline(np.asarray(site.rp_x_m), np.asarray(site.rp_y_m))
    code = scheme_code(scheme)
    site.port_building = [0] * site.n_ports
    site.port_outdoor = [0] * site.n_ports
    site.port_steps = [
        (s or _stair_steps(site, i)) if site.port_kind[i] == site_t.PORT_STAIRS else s
        for i, s in enumerate(site.port_steps or [0] * site.n_ports)
    ]
    site.port_lo_x_m = (
        list(site.port_lo_x_m) if len(site.port_lo_x_m) == site.n_ports else list(site.port_x_m)
    )
    site.port_lo_y_m = (
        list(site.port_lo_y_m) if len(site.port_lo_y_m) == site.n_ports else list(site.port_y_m)
    )
    site.port_hi_x_m = (
        list(site.port_hi_x_m) if len(site.port_hi_x_m) == site.n_ports else list(site.port_x_m)
    )
    site.port_hi_y_m = (
        list(site.port_hi_y_m) if len(site.port_hi_y_m) == site.n_ports else list(site.port_y_m)
    )
    rp_floor, bfl = np.asarray(site.rp_floor), np.asarray(site.beacon_floor)
    contexts = []
    for i in range(site.n_floors):
        f = site.lowest_floor + i
        method = fix_t.METHOD_BLE if np.any(bfl == f) else fix_t.METHOD_WIFI
        contexts.append(_Context(site_t.CONTEXT_FLOOR, 0, f, code, method, rp_floor == f, bfl == f))
    _write(site, [site.name or "building"], [outline], contexts, ble_placed)
    return site


def context_map_summary(site: site_t) -> dict[str, Any]:
    """The context map of a site file for ``radiomap show``: contexts (kind, building, floor, LSD,
    CDD, members) and ports with their extras."""
    names = list(site.building_name)
    members = np.bincount(np.asarray(site.cdd_context, np.int64), minlength=site.n_contexts)
    contexts = []
    for i in range(site.n_contexts):
        b = site.context_building[i]
        contexts.append(
            {
                "kind": CONTEXT_KINDS.get(site.context_kind[i], "?"),
                "building": names[b] if 0 <= b < len(names) else None,
                "floor": site.context_floor[i],
                "scheme": scheme_name(site.context_scheme[i]),
                "method": CONTEXT_METHODS.get(site.context_method[i], "?"),
                "cdd_method": CONTEXT_METHODS.get(site.context_cdd_method[i], "?"),
                "members": int(members[i]),
                "min_hits": site.context_cdd_min_hits[i],
                "identifiable": bool(members[i]) or site.context_cdd_method[i] == fix_t.METHOD_GNSS,
            }
        )
    neighbours: dict[int, list[int]] = {i: [] for i in range(site.n_ports)}
    for a, b in zip(site.link_a, site.link_b):
        neighbours[a].append(b)
        neighbours[b].append(a)
    ports = [
        {
            "kind": {1: "door", 2: "stairs", 3: "elevator"}.get(site.port_kind[i], "?"),
            "floors": (site.port_floor_lo[i], site.port_floor_hi[i]),
            "building": names[site.port_building[i]] if 0 <= site.port_building[i] < len(names) else None,
            "outdoor": bool(site.port_outdoor[i]),
            "steps": site.port_steps[i],
            "links": sorted(neighbours[i]),
        }
        for i in range(site.n_ports)
    ]
    return {
        "contexts": contexts,
        "buildings": names,
        "ports": ports,
        "n_links": site.n_links,
        "n_cdd": site.n_cdd,
    }
