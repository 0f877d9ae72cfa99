"""The survey route: the surveyor's walk over the calibration points of a survey.

One leg from each point to the next along the shortest path over the grid (moves between neighbouring
points that cross no wall), points in greedy nearest-next order (ties: the row-by-row serpentine
order); a ``SurveyStop`` at every point (the walker stands there, turns through the orientations and
scans: ``survey_stops.py``); between floors the surveyor walks into the elevator cab and rides (a
``LegBreak("elevator")``). The route types are in ``route.py``.
"""

from __future__ import annotations

import math

import numpy as np

from .route import Leg, LegBreak, Polyline, Route, SurveyStop, wrap_angle
from .world import World


def _segment_crosses(a, b, walls: np.ndarray) -> bool:
    """Does the segment a-b cross or touch a wall segment?"""
    if len(walls) == 0:
        return False
    x0, y0, x1, y1 = walls.T

    def orient(ox, oy, px, py, qx, qy):
        return (px - ox) * (qy - oy) - (py - oy) * (qx - ox)

    d1 = orient(x0, y0, x1, y1, a[0], a[1])
    d2 = orient(x0, y0, x1, y1, b[0], b[1])
    d3 = orient(a[0], a[1], b[0], b[1], x0, y0)
    d4 = orient(a[0], a[1], b[0], b[1], x1, y1)
    return bool(np.any((d1 * d2 <= 0) & (d3 * d4 <= 0)))


def _grid_paths(xy: np.ndarray, spacing_m: float, walls: np.ndarray):
    """Shortest paths over the graph of neighbouring points (≤ 1.01 × spacing apart, no wall between)."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import shortest_path

    n = len(xy)
    d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    rows, cols, vals = [], [], []
    for i in range(n):
        for j in np.flatnonzero((d[i] > 1e-9) & (d[i] <= 1.01 * spacing_m)).tolist():
            if j > i and not _segment_crosses(xy[i], xy[j], walls):
                rows += [i, j]
                cols += [j, i]
                vals += [d[i, j], d[i, j]]
    graph = csr_matrix((vals, (rows, cols)), shape=(n, n))
    dist, pred = shortest_path(graph, directed=False, return_predecessors=True)
    return dist, pred


def _path_nodes(pred: np.ndarray, i: int, j: int) -> list[int]:
    out = [j]
    while out[-1] != i:
        out.append(int(pred[i, out[-1]]))
    return out[::-1]


def _clean(points: list) -> list:
    """Drop repeated waypoints and waypoints where the path would reverse (a U-turn is not a corner)."""
    pts = []
    for p in points:
        if not pts or math.hypot(p[0] - pts[-1][0], p[1] - pts[-1][1]) > 1e-9:
            pts.append((float(p[0]), float(p[1])))
    changed = True
    while changed and len(pts) > 2:
        changed = False
        for k in range(1, len(pts) - 1):
            a = math.atan2(pts[k][1] - pts[k - 1][1], pts[k][0] - pts[k - 1][0])
            b = math.atan2(pts[k + 1][1] - pts[k][1], pts[k + 1][0] - pts[k][0])
            if abs(abs(wrap_angle(b - a)) - math.pi) < 1e-6:
                del pts[k]
                changed = True
                break
    return pts


def _visit_order(xy: np.ndarray, spacing_m: float, walls: np.ndarray, ref: np.ndarray, floor: int):
    """Grid paths (predecessors) and the greedy nearest-next visiting order of one floor's points,
    starting at the point nearest ``ref`` (ties: the row-by-row serpentine order)."""
    dist, pred = _grid_paths(xy, spacing_m, walls)
    # serpentine rank: rows by y, x ascending on even rows, descending on odd rows
    ys = np.unique(np.round(xy[:, 1], 6))
    row = np.searchsorted(ys, np.round(xy[:, 1], 6))
    rank = np.lexsort((np.where(row % 2 == 0, xy[:, 0], -xy[:, 0]), row))
    rank_of = np.empty(len(xy), int)
    rank_of[rank] = np.arange(len(xy))
    cur = int(np.lexsort((rank_of, np.round(np.hypot(*(xy - ref).T), 6)))[0])
    seq = [cur]
    left = set(range(len(xy))) - {cur}
    while left:
        cand = sorted(left, key=lambda j: (round(float(dist[cur, j]), 6), rank_of[j]))
        nxt = cand[0]
        if not np.isfinite(dist[cur, nxt]):
            raise ValueError(
                f"calibration points of floor {floor} are not connected at {spacing_m} m spacing"
            )
        seq.append(nxt)
        left.remove(nxt)
        cur = nxt
    return pred, seq


def survey_route(world: World, points: np.ndarray, spacing_m: float, radius_m: float) -> Route:
    """The surveyor's walk over ``points`` (n, 3: x, y, floor), floor by floor (see the module docstring)."""
    if len(points) < 2:
        raise ValueError("a survey needs at least two calibration points")
    if world.survey_parts is not None:
        return _parts_route(world, points, spacing_m, radius_m)
    floors = sorted({int(f) for f in points[:, 2]})
    if len(floors) > 1 and world.elevator is None:
        raise ValueError(f"world {world.name!r} has no elevator to survey several floors")
    order: list[int] = []
    legs: list[Leg] = []
    breaks: list[LegBreak] = []
    paths_per_floor = {}
    entry = np.asarray(world.start_xy_m, float)
    if world.elevator is not None:
        el = world.elevator
        x_door = float(world.loop_corners_m[0][0])  # the corridor centre line in front of the cab door
        door, cab = (x_door, el.door_y_m), (el.x_m, el.door_y_m)
    for fi, f in enumerate(floors):
        idx = np.flatnonzero(points[:, 2] == f)
        xy = points[idx, :2]
        ref = entry if fi == 0 else np.asarray(door)
        pred, seq = _visit_order(xy, spacing_m, world.walls_m, ref, f)
        paths_per_floor[f] = (idx, xy, pred, seq)
    z = {f: f * world.storey_m for f in floors}
    stop_of = {}
    for f in floors:
        idx, xy, pred, seq = paths_per_floor[f]
        for j in seq:
            stop_of[(f, j)] = SurveyStop(index=len(order), x_m=float(xy[j, 0]), y_m=float(xy[j, 1]), floor=f)
            order.append(int(idx[j]))
    pending_exit = None  # waypoints from the cab out to the corridor, after an elevator ride
    for fi, f in enumerate(floors):
        idx, xy, pred, seq = paths_per_floor[f]
        if pending_exit is not None:
            first = xy[seq[0]]
            near = int(np.argmin(np.hypot(*(xy - np.asarray(door)).T)))
            way = (
                pending_exit + [tuple(xy[k]) for k in _path_nodes(pred, near, seq[0])]
                if near != seq[0]
                else pending_exit + [tuple(first)]
            )
            legs.append(Leg(path=Polyline(_clean(way), radius_m), z0_m=z[f]))
            breaks.append(LegBreak("survey", stop=stop_of[(f, seq[0])]))
        for a, b in zip(seq[:-1], seq[1:]):
            way = [tuple(xy[k]) for k in _path_nodes(pred, a, b)]
            legs.append(Leg(path=Polyline(_clean(way), radius_m), z0_m=z[f]))
            breaks.append(LegBreak("survey", stop=stop_of[(f, b)]))
        if fi + 1 < len(floors):
            near = int(np.argmin(np.hypot(*(xy - np.asarray(door)).T)))
            last = seq[-1]
            way = [tuple(xy[k]) for k in _path_nodes(pred, last, near)] if near != last else [tuple(xy[last])]
            legs.append(Leg(path=Polyline(_clean(way + [door, cab]), radius_m), z0_m=z[f]))
            breaks.append(LegBreak("elevator", dz_m=z[floors[fi + 1]] - z[f]))
            pending_exit = [cab, door]
    end_stop = breaks[-1].stop
    breaks = breaks[:-1]  # the last stop comes after the last leg
    f0, (_, _, _, seq0) = floors[0], paths_per_floor[floors[0]]
    return Route(
        name="survey",
        legs=legs,
        breaks=breaks,
        radius_m=radius_m,
        start_stop=stop_of[(f0, seq0[0])],
        end_stop=end_stop,
        survey_points=points[order],
    )


def _parts_route(world: World, points: np.ndarray, spacing_m: float, radius_m: float) -> Route:
    """The survey of a world with parts (``World.survey_parts``, world_parts.py): each part's points
    (its floor's inside its rectangle) in greedy nearest-next order from the point nearest where the
    surveyor comes in (the start, the elevator door, or the end of the part's ``via_m``); between parts
    the elevator ride (another floor) or the walk along ``via_m`` (the same floor)."""
    el = world.elevator
    door = (float(world.loop_corners_m[0][0]), el.door_y_m) if el is not None else None
    cab = (el.x_m, el.door_y_m) if el is not None else None
    parts = []
    for k, part in enumerate(world.survey_parts):
        x0, y0, x1, y1 = part.area_m
        idx = np.flatnonzero(
            (points[:, 2] == part.floor)
            & (points[:, 0] >= x0)
            & (points[:, 0] <= x1)
            & (points[:, 1] >= y0)
            & (points[:, 1] <= y1)
        )
        if len(idx) == 0:
            continue
        xy = points[idx, :2]
        prev = parts[-1][0] if parts else None
        if prev is None:
            ref = np.asarray(world.start_xy_m, float)
        elif prev.floor != part.floor:
            if door is None:
                raise ValueError(f"world {world.name!r} has no elevator to survey several floors")
            ref = np.asarray(door)
        else:
            if not part.via_m:
                raise ValueError(f"survey part {k} is on the floor of the one before it but has no via_m")
            ref = np.asarray(part.via_m[-1], float)
        pred, seq = _visit_order(xy, spacing_m, world.walls_m, ref, part.floor)
        parts.append((part, idx, xy, pred, seq))
    order: list[int] = []
    stops = []
    for part, idx, xy, _pred, seq in parts:
        stops.append([])
        for j in seq:
            stops[-1].append(SurveyStop(len(order), float(xy[j, 0]), float(xy[j, 1]), part.floor))
            order.append(int(idx[j]))
    legs: list[Leg] = []
    breaks: list[LegBreak] = []
    pending: list = []  # waypoints from where the last part was left to this part's first point
    for pi, (part, _idx, xy, pred, seq) in enumerate(parts):
        z = part.floor * world.storey_m

        def nearest(p, xy=xy):
            return int(np.argmin(np.hypot(*(xy - np.asarray(p, float)).T)))

        if pending:
            near = nearest(pending[-1])
            way = pending + [tuple(xy[k]) for k in _path_nodes(pred, near, seq[0])]
            legs.append(Leg(path=Polyline(_clean(way), radius_m), z0_m=z))
            breaks.append(LegBreak("survey", stop=stops[pi][0]))
        for n, (a, b) in enumerate(zip(seq[:-1], seq[1:])):
            way = [tuple(xy[k]) for k in _path_nodes(pred, a, b)]
            legs.append(Leg(path=Polyline(_clean(way), radius_m), z0_m=z))
            breaks.append(LegBreak("survey", stop=stops[pi][n + 1]))
        if pi + 1 == len(parts):
            break
        nxt = parts[pi + 1][0]
        target = door if nxt.floor != part.floor else nxt.via_m[0]
        near = nearest(target)
        way = [tuple(xy[k]) for k in _path_nodes(pred, seq[-1], near)]
        if nxt.floor != part.floor:
            legs.append(Leg(path=Polyline(_clean(way + [door, cab]), radius_m), z0_m=z))
            breaks.append(LegBreak("elevator", dz_m=(nxt.floor - part.floor) * world.storey_m))
            pending = [cab, door]
        else:
            pending = way + [tuple(p) for p in nxt.via_m]
    end_stop = breaks[-1].stop
    return Route(
        name="survey",
        legs=legs,
        breaks=breaks[:-1],
        radius_m=radius_m,
        start_stop=stops[0][0],
        end_stop=end_stop,
        survey_points=points[order],
    )
