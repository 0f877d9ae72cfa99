"""Floor plans from msindoor's GeoJSON: lon/lat polygons → wall segments in the waypoint frame, with
doors opened where training walks cross a wall.

Mapping (the ILC 2.0 convention): the bounding box of the *floor* feature (the MultiPolygon whose
``properties.type``/``category`` is ``floor``, else the first MultiPolygon) is scaled onto
[0, width] × [0, height] of ``floor_info.json``:
``x = (lon − lon_min) / (lon_max − lon_min) · width``, ``y = (lat − lat_min) / (lat_max − lat_min) ·
height``. The map frame's (0, 0) is then (lat_min, lon_min), x east and y north: the geo-reference is
that origin with rotation 0 (:func:`geo_reference`, which also reports how far the frame's scale is
from the local tangent plane's metres of :func:`~stridefix_analyzer.datasets.gsd_convert.project`).

Walls: every edge of the outline's rings and of the room polygons (``Polygon`` features), simplified
per ring — a vertex closer than :data:`COLLINEAR_TOL_M` to the chord of its neighbours is dropped (a
collinear run becomes one edge), then edges shorter than :data:`MIN_WALL_M` are dropped and edges
shared by two polygons kept once. Rooms smaller than ``min_room_area_m2`` can be left out.

Doors are not in the GeoJSON: :func:`open_walls` cuts a gap of :data:`DOOR_WIDTH_M` centred on each
crossing of a wall by a truth segment (linear interpolation between consecutive waypoints on one
floor) of the training walks. :func:`held_out_crossing` measures, leave one walk out, the fraction
of a walk's truth segments that cross a wall its fold kept.

Cost: intersections are numpy-vectorised, O(W·S) for W walls and S segments, in blocks of
:data:`BLOCK` segments (memory O(W·BLOCK)).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Collection, Mapping, Sequence
from typing import Any

import numpy as np

#: A vertex this close to the chord of its neighbours lies on a straight wall [m] (GeoJSON vertices
#: are stored to 1e-6 deg ≈ 0.1 m; half of that is digitisation noise, not a corner).
COLLINEAR_TOL_M = 0.05
#: Edges shorter than this are dropped [m]: shorter than a shoulder width, they stop no walker and
#: only cost the core's wall index.
MIN_WALL_M = 0.3
#: Gap opened per crossing [m]: a shop door or an entrance (1–2.5 m) plus the corner the linearly
#: interpolated truth cuts on either side.
DOOR_WIDTH_M = 2.0
#: Truth segments intersected per block (bounds memory at W × BLOCK).
BLOCK = 512


class FloorPlanError(Exception):
    """A floor plan file cannot be read (names the file, the feature and the field)."""


@dataclasses.dataclass(frozen=True)
class GeoFloorPlan:
    """A floor plan in the map frame [m]: outline polygons (each a list of rings, exterior first) and
    rooms (exterior rings with their areas [m²]); the lon/lat box mapped onto the extent."""

    width_m: float
    height_m: float
    lon_min_deg: float
    lon_max_deg: float
    lat_min_deg: float
    lat_max_deg: float
    outline: list[list[np.ndarray]]
    rooms: list[np.ndarray]
    room_area_m2: np.ndarray

    def to_map(self, lon_deg: Any, lat_deg: Any) -> np.ndarray:
        """(k, 2) map-frame metres of lon/lat [deg]."""
        lon, lat = np.asarray(lon_deg, float), np.asarray(lat_deg, float)
        x = (lon - self.lon_min_deg) / (self.lon_max_deg - self.lon_min_deg) * self.width_m
        y = (lat - self.lat_min_deg) / (self.lat_max_deg - self.lat_min_deg) * self.height_m
        return np.column_stack([x, y])


def _ring(path: str, where: str, coords: Any) -> np.ndarray:
    try:
        r = np.asarray(coords, dtype=float)
    except (TypeError, ValueError):
        raise FloorPlanError(f"{path}: {where}: coordinates: not a list of [lon, lat]") from None
    if r.ndim != 2 or r.shape[1] < 2 or len(r) < 3 or not np.isfinite(r[:, :2]).all():
        raise FloorPlanError(f"{path}: {where}: coordinates: needs >= 3 finite [lon, lat] points")
    return r[:, :2]


def _area(ring: np.ndarray) -> float:
    x, y = ring[:, 0], ring[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2.0)


def read_geojson_plan(
    geojson: Mapping[str, Any], width_m: float, height_m: float, path: str = "geojson_map.json"
) -> GeoFloorPlan:
    """The plan of a GeoJSON FeatureCollection on a floor of ``width_m`` × ``height_m`` (module
    docstring). Raises :class:`FloorPlanError` naming ``path``, the feature and the field."""
    if not (width_m > 0 and height_m > 0 and math.isfinite(width_m) and math.isfinite(height_m)):
        raise FloorPlanError(f"{path}: floor extent {width_m} x {height_m} m must be > 0")
    feats = geojson.get("features") if isinstance(geojson, Mapping) else None
    if not isinstance(feats, list):
        raise FloorPlanError(f"{path}: features: missing (not a GeoJSON FeatureCollection)")
    polys: list[tuple[list[list[np.ndarray]], bool]] = []
    rooms: list[np.ndarray] = []
    for i, f in enumerate(feats):
        geom = f.get("geometry") if isinstance(f, Mapping) else None
        where = f"feature {i}"
        if not isinstance(geom, Mapping) or "type" not in geom:
            raise FloorPlanError(f"{path}: {where}: geometry.type: missing")
        kind = geom["type"]
        if kind == "MultiPolygon":
            props = f.get("properties") or {}
            is_floor = "floor" in (props.get("type"), props.get("category"))
            coords = geom.get("coordinates") or []
            polys.append(
                ([[_ring(path, f"{where} ring {k}", r) for k, r in enumerate(p)] for p in coords], is_floor)
            )
        elif kind == "Polygon":
            coords = geom.get("coordinates") or []
            if not coords:
                raise FloorPlanError(f"{path}: {where}: coordinates: empty Polygon")
            rooms.append(_ring(path, where, coords[0]))
    if not polys:
        raise FloorPlanError(f"{path}: no MultiPolygon feature (the floor outline)")
    floor_i = next((k for k, (_, is_floor) in enumerate(polys) if is_floor), 0)
    outline_deg = polys[floor_i][0]
    pts = np.concatenate([r for p in outline_deg for r in p])
    (lon0, lat0), (lon1, lat1) = pts.min(axis=0), pts.max(axis=0)
    if not (lon1 > lon0 and lat1 > lat0):
        raise FloorPlanError(f"{path}: floor outline has an empty bounding box")
    plan = GeoFloorPlan(float(width_m), float(height_m), lon0, lon1, lat0, lat1, [], [], np.zeros(0))
    outline = [[plan.to_map(r[:, 0], r[:, 1]) for r in p] for p in outline_deg]
    rooms_m = [plan.to_map(r[:, 0], r[:, 1]) for r in rooms]
    return dataclasses.replace(
        plan, outline=outline, rooms=rooms_m, room_area_m2=np.array([_area(r) for r in rooms_m])
    )


def geo_reference(plan: GeoFloorPlan) -> dict[str, Any]:
    """site_t geo fields of the plan's frame (origin = its (0, 0), rotation 0: x east, y north) and
    ``scale`` = map metres per tangent-plane metre along x and y (1 = the frame is true metres)."""
    from stridefix_common.geodesy import project

    ex, ny = project([plan.lat_max_deg], [plan.lon_max_deg], plan.lat_min_deg, plan.lon_min_deg)
    return {
        "fields": {
            "has_geo": True,
            "origin_lat_deg": float(plan.lat_min_deg),
            "origin_lon_deg": float(plan.lon_min_deg),
            "origin_alt_m": 0.0,
            "geo_rotation_deg": 0.0,
        },
        "scale": [plan.width_m / float(ex[0]), plan.height_m / float(ny[0])],
    }


def _inside_ring(ring: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Even-odd ray casting of points (k, 2) against a ring (closed or not)."""
    a, b = ring, np.roll(ring, -1, axis=0)
    x, y = xy[:, 0:1], xy[:, 1:2]
    crosses = (a[None, :, 1] > y) != (b[None, :, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xi = a[None, :, 0] + (y - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (
            b[None, :, 1] - a[None, :, 1]
        )
    return (np.sum(crosses & (x < xi), axis=1) % 2) == 1


def inside_outline(plan: GeoFloorPlan, xy: Any) -> np.ndarray:
    """Which points (k, 2) [m] lie inside the floor outline (an exterior ring and none of its holes)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    out = np.zeros(len(xy), dtype=bool)
    for poly in plan.outline:
        ins = _inside_ring(poly[0], xy)
        for hole in poly[1:]:
            ins &= ~_inside_ring(hole, xy)
        out |= ins
    return out


def simplify_ring(ring: np.ndarray, tol_m: float = COLLINEAR_TOL_M) -> np.ndarray:
    """The ring's corners (k, 2), open (last ≠ first): vertices within ``tol_m`` of the chord of
    their kept neighbours are dropped until none is."""
    r = np.asarray(ring, float)
    if len(r) > 1 and np.allclose(r[0], r[-1]):
        r = r[:-1]
    keep = list(range(len(r)))
    changed = True
    while changed and len(keep) > 3:
        changed = False
        for k in range(len(keep)):
            p, q, s = r[keep[k - 1]], r[keep[k]], r[keep[(k + 1) % len(keep)]]
            chord = s - p
            ln = math.hypot(*chord)
            d = math.hypot(*(q - p)) if ln == 0 else abs(chord[0] * (q - p)[1] - chord[1] * (q - p)[0]) / ln
            if d < tol_m:
                del keep[k]
                changed = True
                break
    return r[keep]


def plan_walls(
    plan: GeoFloorPlan,
    *,
    min_room_area_m2: float = 0.0,
    min_wall_m: float = MIN_WALL_M,
    tol_m: float = COLLINEAR_TOL_M,
) -> np.ndarray:
    """Wall segments (n, 4) [x0, y0, x1, y1] m of the outline and the rooms of at least
    ``min_room_area_m2`` (``inf``: the outline only); simplified and de-duplicated (module docstring)."""
    rings = [r for p in plan.outline for r in p]
    rings += [r for r, a in zip(plan.rooms, plan.room_area_m2) if a >= min_room_area_m2]
    segs = []
    for ring in rings:
        c = simplify_ring(ring, tol_m)
        segs.append(np.column_stack([c, np.roll(c, -1, axis=0)]))
    w = np.concatenate(segs) if segs else np.zeros((0, 4))
    w = w[np.hypot(w[:, 2] - w[:, 0], w[:, 3] - w[:, 1]) >= min_wall_m]
    # one copy of an edge two polygons share (either direction), at 1 cm
    a, b = np.round(w[:, :2], 2), np.round(w[:, 2:], 2)
    swap = (a[:, 0] > b[:, 0]) | ((a[:, 0] == b[:, 0]) & (a[:, 1] > b[:, 1]))
    key = np.where(swap[:, None], np.column_stack([b, a]), np.column_stack([a, b]))
    _, first = np.unique(key, axis=0, return_index=True)
    return w[np.sort(first)]


def truth_segments(
    walks_xy: Sequence[Any], walks_floor: Sequence[Any] | None = None
) -> dict[str, np.ndarray]:
    """Truth segments of walks: between consecutive waypoints (k_i, 2) on one floor, with no zero
    length. Returns ``seg`` (s, 4) [x0, y0, x1, y1], ``walk`` (s,) index into ``walks_xy``, ``floor``."""
    segs, owner, floors = [], [], []
    for i, xy in enumerate(walks_xy):
        xy = np.asarray(xy, float).reshape(-1, 2)
        fl = np.zeros(len(xy), np.int64) if walks_floor is None else np.asarray(walks_floor[i], np.int64)
        if len(xy) < 2:
            continue
        s = np.column_stack([xy[:-1], xy[1:]])
        ok = (fl[:-1] == fl[1:]) & (np.hypot(s[:, 2] - s[:, 0], s[:, 3] - s[:, 1]) > 0)
        segs.append(s[ok])
        owner.append(np.full(int(ok.sum()), i))
        floors.append(fl[:-1][ok])
    cat = lambda v, shape: np.concatenate(v) if v else np.zeros(shape)  # noqa: E731
    return {
        "seg": cat(segs, (0, 4)),
        "walk": cat(owner, 0).astype(np.int64),
        "floor": cat(floors, 0).astype(np.int64),
    }


def crossings(walls: np.ndarray, segs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every proper intersection of walls (w, 4) with segments (s, 4): (wall index, distance along
    the wall from its first end [m], segment index), vectorised in blocks of :data:`BLOCK` segments."""
    walls, segs = np.asarray(walls, float).reshape(-1, 4), np.asarray(segs, float).reshape(-1, 4)
    p, r = walls[:, None, :2], walls[:, None, 2:] - walls[:, None, :2]
    out_w, out_u, out_s = [], [], []
    for s0 in range(0, len(segs), BLOCK):
        blk = segs[s0 : s0 + BLOCK]
        q, d = blk[None, :, :2], blk[None, :, 2:] - blk[None, :, :2]
        den = r[..., 0] * d[..., 1] - r[..., 1] * d[..., 0]
        qp = q - p
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (qp[..., 0] * d[..., 1] - qp[..., 1] * d[..., 0]) / den
            u = (qp[..., 0] * r[..., 1] - qp[..., 1] * r[..., 0]) / den
        hit = (den != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
        wi, si = np.nonzero(hit)
        out_w.append(wi)
        out_u.append(t[wi, si] * np.hypot(r[wi, 0, 0], r[wi, 0, 1]))
        out_s.append(si + s0)
    if not out_w:
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.int64)
    return np.concatenate(out_w), np.concatenate(out_u), np.concatenate(out_s)


def open_walls(
    walls: np.ndarray,
    cross_wall: np.ndarray,
    cross_u_m: np.ndarray,
    *,
    door_width_m: float = DOOR_WIDTH_M,
    min_wall_m: float = MIN_WALL_M,
) -> tuple[np.ndarray, int]:
    """Walls (w, 4) with a gap of ``door_width_m`` centred on each crossing (wall index, distance
    along it [m]); pieces shorter than ``min_wall_m`` go. Returns (walls (m, 4), openings: the merged
    gaps cut)."""
    walls = np.asarray(walls, float).reshape(-1, 4)
    crossed = np.unique(cross_wall)
    keep = np.ones(len(walls), bool)
    keep[crossed] = False
    pieces = [walls[keep]]
    openings = 0
    half = door_width_m / 2.0
    for wi in crossed.tolist():
        x0, y0, x1, y1 = walls[wi]
        length = math.hypot(x1 - x0, y1 - y0)
        us = np.sort(cross_u_m[cross_wall == wi])
        gaps: list[list[float]] = []
        for u in us.tolist():
            lo, hi = max(0.0, u - half), min(length, u + half)
            if gaps and lo <= gaps[-1][1]:
                gaps[-1][1] = max(gaps[-1][1], hi)
            else:
                gaps.append([lo, hi])
        openings += len(gaps)
        edges = [0.0] + [v for g in gaps for v in g] + [length]
        for a, b in zip(edges[0::2], edges[1::2]):
            if b - a >= min_wall_m:
                fa, fb = a / length, b / length
                pieces.append(
                    np.array(
                        [[x0 + fa * (x1 - x0), y0 + fa * (y1 - y0), x0 + fb * (x1 - x0), y0 + fb * (y1 - y0)]]
                    )
                )
    return np.concatenate(pieces), openings


@dataclasses.dataclass(frozen=True)
class DoorSurvey:
    """The walls of one floor and every crossing of them by every walk's truth segments, computed
    once; each fold opens the crossings of its training walks (:meth:`fold_walls`)."""

    walls: np.ndarray
    segments: dict[str, np.ndarray]
    cross_wall: np.ndarray
    cross_u_m: np.ndarray
    cross_walk: np.ndarray

    @classmethod
    def of(
        cls, walls: np.ndarray, walks_xy: Sequence[Any], walks_floor: Sequence[Any] | None = None
    ) -> DoorSurvey:
        segs = truth_segments(walks_xy, walks_floor)
        cw, cu, cs = crossings(walls, segs["seg"])
        return cls(np.asarray(walls, float), segs, cw, cu, segs["walk"][cs])

    def fold_walls(self, held: int | Collection[int] | None, **kw: Any) -> tuple[np.ndarray, int]:
        """Walls opened by every walk but ``held`` (one index or several; None: all walks);
        (walls, openings)."""
        out = [held] if isinstance(held, int) else list(held or [])
        use = ~np.isin(self.cross_walk, out)
        return open_walls(self.walls, self.cross_wall[use], self.cross_u_m[use], **kw)

    def held_out_crossing(self, **kw: Any) -> dict[str, Any]:
        """Leave one walk out: per walk, its truth segments crossing a wall its fold kept. Returns
        ``fraction`` (pooled), ``segments``, ``crossing`` and per-walk ``per_walk`` fractions."""
        n_walks = int(self.segments["walk"].max()) + 1 if len(self.segments["walk"]) else 0
        total = crossing = 0
        per_walk = []
        for j in range(n_walks):
            mine = self.segments["walk"] == j
            if not mine.any():
                continue
            walls, _ = self.fold_walls(j, **kw)
            w, _, s = crossings(walls, self.segments["seg"][mine])
            hit = len(np.unique(s))
            total += int(mine.sum())
            crossing += hit
            per_walk.append(hit / int(mine.sum()))
        return {
            "fraction": crossing / total if total else math.nan,
            "segments": total,
            "crossing": crossing,
            "per_walk": per_walk,
        }


def wall_fields(walls: np.ndarray, floor: int) -> dict[str, Any]:
    """site_t wall fields of segments (n, 4) on one floor."""
    w = np.asarray(walls, float).reshape(-1, 4)
    return {
        "wall_x0_m": w[:, 0].tolist(),
        "wall_y0_m": w[:, 1].tolist(),
        "wall_x1_m": w[:, 2].tolist(),
        "wall_y1_m": w[:, 3].tolist(),
        "wall_floor": [int(floor)] * len(w),
    }


def load_plan(geojson_path: str, info_path: str | None = None) -> GeoFloorPlan:
    """Read ``geojson_map.json`` and ``floor_info.json`` (default: the one beside it). Raises
    :class:`FloorPlanError` naming the file and field."""
    import json
    import os

    info_path = info_path or os.path.join(os.path.dirname(os.path.abspath(geojson_path)), "floor_info.json")
    docs = []
    for p in (geojson_path, info_path):
        try:
            with open(p, encoding="utf-8") as f:
                docs.append(json.load(f))
        except OSError as exc:
            raise FloorPlanError(f"{p}: cannot read: {exc.strerror or exc}") from None
        except ValueError as exc:
            raise FloorPlanError(f"{p}: not JSON: {exc}") from None
    try:
        width, height = float(docs[1]["map_info"]["width"]), float(docs[1]["map_info"]["height"])
    except (KeyError, TypeError, ValueError):
        raise FloorPlanError(f"{info_path}: map_info.width/height: missing or not numbers") from None
    return read_geojson_plan(docs[0], width, height, geojson_path)


def site_plan(
    plan: GeoFloorPlan,
    walks_xy: Sequence[Any],
    walks_floor: Sequence[Any] | None,
    floor: int,
    *,
    min_room_area_m2: float = 0.0,
    crossing_check: bool = True,
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The site fields (walls opened where the walks cross them, geo-reference) and the report
    (waypoints inside the outline, wall counts, openings, held-out crossing fraction, geo scale)."""
    walls = plan_walls(plan, min_room_area_m2=min_room_area_m2)
    survey = DoorSurvey.of(walls, walks_xy, walks_floor)
    opened, openings = survey.fold_walls(None)
    pts = [np.asarray(w, float).reshape(-1, 2) for w in walks_xy]
    xy = np.concatenate(pts) if pts else np.zeros((0, 2))
    geo = geo_reference(plan)
    report: dict[str, Any] = {
        "floor": int(floor),
        "waypoints_inside_outline": float(inside_outline(plan, xy).mean()) if len(xy) else math.nan,
        "waypoints": len(xy),
        "rooms": len(plan.rooms),
        "min_room_area_m2": min_room_area_m2,
        "edges_raw": sum(len(r) - 1 for p in plan.outline for r in p) + sum(len(r) - 1 for r in plan.rooms),
        "walls_simplified": len(walls),
        "walls_opened": len(opened),
        "openings": openings,
        "crossings": len(survey.cross_wall),
        "truth_segments": len(survey.segments["seg"]),
        "geo_scale": geo["scale"],
    }
    if crossing_check:
        h = survey.held_out_crossing()
        report["held_out_crossing_fraction"] = h["fraction"]
    return {**wall_fields(opened, floor), **geo["fields"]}, report
