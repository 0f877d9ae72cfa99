"""Routes: where the walker goes, as plan-view paths with rounded corners and a height profile.

A route is a sequence of legs. A leg is a polyline of waypoints whose corners are circular arcs
(fillets; the radius is shrunk if a corner is too close to its neighbours), so heading is continuous
along a leg and the curvature is 1/r on arcs, 0 on straights (signed: + = left turn, CCW). A leg may
contain stair flights: straight stretches along which the walking surface rises linearly (rise / run of
the flight). The height profile is smoothed over ``SLOPE_BLEND_M`` at each slope change, so vertical
velocity is continuous (C1). Between two legs the walker stands still: the next leg starts where the
previous one ended, possibly facing another way (a turn in place) and at another height (an elevator
ride). Distances along a leg are ``d`` [m], along the whole route ``s`` [m].

Routes built here (from the world's geometry):

* ``loop``: laps of the corridor loop of floor 0, counter-clockwise, starting on its bottom straight;
* ``tour``: a lap of floor 0 from the stairwell door, the dog-leg staircase up to floor 1, a lap of
  floor 1 into the elevator cab (leg 1); the elevator down to floor 0, then out of the cab and a
  partial lap of floor 0 (leg 2);
* ``track``: the world's track (``World.track_m``, e.g. the aadr2015 foyer), one leg; its surveyed
  reference points (``World.reference_points_m``, on straight stretches) become ``Route.marks``;
* ``legs``: the world's walk as legs (``World.walk_legs``, world_parts.py: e.g. campus2, outdoors →
  a building → stairs → elevator rides → outdoors → another building), an elevator ride between legs,
  the legs' waits as pauses (``Route.pauses``);
* ``survey``: the surveyor's walk over calibration points (``survey_route.py``), a ``SurveyStop`` at
  every point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .world import World

SLOPE_BLEND_M = 0.3  # height profile: slope changes are blended over this distance
HEIGHT_GRID_M = 0.01  # height profile table resolution
STAIRWELL_RADIUS_M = 0.6


def wrap_angle(a: float) -> float:
    """``a`` wrapped to (−π, π] [rad]."""
    return math.atan2(math.sin(a), math.cos(a))


class Polyline:
    """A path through waypoints with circular fillets at the corners.

    ``points``: (x, y) or (x, y, radius) tuples; the radius (default ``radius_m``) applies to the corner
    at that waypoint. Collinear waypoints are allowed (no arc). ``vertex_d[i]``: distance along the path
    at waypoint i (arc midpoint for a corner).
    """

    def __init__(self, points, radius_m: float):
        pts = [(float(p[0]), float(p[1])) for p in points]
        radii = [float(p[2]) if len(p) > 2 else radius_m for p in points]
        if len(pts) < 2:
            raise ValueError("a path needs at least two waypoints")
        P = np.asarray(pts)
        seg = np.diff(P, axis=0)
        seg_len = np.hypot(seg[:, 0], seg[:, 1])
        if np.any(seg_len <= 1e-9):
            raise ValueError("consecutive waypoints must differ")
        ang = np.arctan2(seg[:, 1], seg[:, 0])
        n = len(P)
        turn = np.zeros(n)
        tan_d = np.zeros(n)
        rad = np.zeros(n)
        for i in range(1, n - 1):
            turn[i] = wrap_angle(ang[i] - ang[i - 1])
            if abs(turn[i]) < 1e-9:
                turn[i] = 0.0
            elif abs(abs(turn[i]) - math.pi) < 1e-9:
                raise ValueError(f"waypoint {i}: a path cannot reverse (split it into two legs)")
        for i in range(1, n - 1):
            if turn[i] == 0.0:
                continue
            r = radii[i]
            # a segment is shared with the corner at its other end, if there is one
            room = min(
                seg_len[i - 1] * (0.5 if turn[i - 1] else 1.0), seg_len[i] * (0.5 if turn[i + 1] else 1.0)
            )
            r = min(r, room / math.tan(0.5 * abs(turn[i])))
            rad[i] = r
            tan_d[i] = r * math.tan(0.5 * abs(turn[i]))
        # pieces: ('L', d0, length, x0, y0, heading) and ('A', d0, length, cx, cy, r, sign, heading_in)
        pieces = []
        heading = float(ang[0])
        d = 0.0
        vertex_d = [0.0]
        for i in range(n - 1):
            u = seg[i] / seg_len[i]
            a0 = P[i] + tan_d[i] * u
            ln = seg_len[i] - tan_d[i] - tan_d[i + 1]
            if ln > 1e-12:
                pieces.append(("L", d, ln, float(a0[0]), float(a0[1]), heading))
                d += ln
            j = i + 1
            if j < n - 1 and turn[j] != 0.0:
                sgn = 1.0 if turn[j] > 0 else -1.0
                r = rad[j]
                t0 = P[j] - tan_d[j] * u
                cx = t0[0] - sgn * r * math.sin(heading)
                cy = t0[1] + sgn * r * math.cos(heading)
                arc = r * abs(turn[j])
                pieces.append(("A", d, arc, float(cx), float(cy), r, sgn, heading))
                vertex_d.append(d + 0.5 * arc)
                d += arc
                heading += turn[j]
            elif j < n - 1:
                vertex_d.append(d)
        vertex_d.append(d)
        self.points = P
        self.pieces = pieces
        self.length_m = d
        self.vertex_d = np.asarray(vertex_d)
        self.heading_start = float(ang[0])
        self.heading_end = heading
        self._starts = np.array([p[1] for p in pieces])

    def pose(self, d_m):
        """Pose at distance ``d_m`` (clipped to the path): x_m, y_m, heading_rad (unwrapped), curvature_1pm."""
        d = np.clip(np.asarray(d_m, dtype=float), 0.0, self.length_m)
        x = np.empty_like(d)
        y = np.empty_like(d)
        hd = np.empty_like(d)
        k = np.zeros_like(d)
        idx = np.clip(np.searchsorted(self._starts, d, side="right") - 1, 0, len(self.pieces) - 1)
        # the samples of each piece, in their order (a stable sort: O(n log n) however many pieces a
        # long walk has, and the same arrays as the mask idx == i gave, so the same numbers)
        order = np.argsort(idx, kind="stable")
        bounds = np.searchsorted(idx[order], np.arange(len(self.pieces) + 1), side="left")
        for i, pc in enumerate(self.pieces):
            if bounds[i] == bounds[i + 1]:
                continue
            m = order[bounds[i] : bounds[i + 1]]
            e = d[m] - pc[1]
            if pc[0] == "L":
                _, _, _, x0, y0, h = pc
                x[m] = x0 + e * math.cos(h)
                y[m] = y0 + e * math.sin(h)
                hd[m] = h
            else:
                _, _, _, cx, cy, r, sgn, h0 = pc
                h = h0 + sgn * e / r
                x[m] = cx + sgn * r * np.sin(h)
                y[m] = cy - sgn * r * np.cos(h)
                hd[m] = h
                k[m] = sgn / r
        return x, y, hd, k


@dataclass
class Flight:
    """A stair flight along a leg: from d_a to d_b the walking surface rises by ``rise_m``."""

    d_a: float
    d_b: float
    rise_m: float


@dataclass
class Leg:
    path: Polyline
    z0_m: float  # level of the walking surface at the leg's start [m above floor 0]
    flights: list[Flight] = field(default_factory=list)
    length_m: float = 0.0  # walked length (<= path length; 0 = the whole path)

    def __post_init__(self):
        if self.length_m <= 0:
            self.length_m = self.path.length_m
        n = int(math.ceil(self.length_m / HEIGHT_GRID_M)) + 1
        grid = np.linspace(0.0, self.length_m, n)
        h = np.full(n, self.z0_m)
        for f in self.flights:
            h += f.rise_m * np.clip((grid - f.d_a) / (f.d_b - f.d_a), 0.0, 1.0)
        if self.flights:
            w = max(1, int(round(SLOPE_BLEND_M / HEIGHT_GRID_M)))
            pad = np.concatenate([np.full(w, h[0]), h, np.full(w, h[-1])])
            ker = np.ones(w) / w
            h = np.convolve(pad, ker, mode="same")[w:-w]
        self._grid = grid
        self._h = h
        self._dh = np.gradient(h, grid)
        self._d2h = np.gradient(self._dh, grid)

    @property
    def z_end_m(self) -> float:
        return float(self._h[-1])

    def height(self, d_m):
        """Walking-surface level h, dh/dd and d²h/dd² at distances ``d_m`` along the leg."""
        d = np.asarray(d_m, dtype=float)
        return (
            np.interp(d, self._grid, self._h),
            np.interp(d, self._grid, self._dh),
            np.interp(d, self._grid, self._d2h),
        )


@dataclass(frozen=True)
class SurveyStop:
    """A calibration point where the surveyor stands, turns in place and scans."""

    index: int  # into the route's survey points
    x_m: float
    y_m: float
    floor: int


@dataclass
class LegBreak:
    """What happens between leg i and leg i + 1 (the walker stands; ``dz_m`` = elevator ride)."""

    kind: str  # "elevator", "turn" or "survey" (a SurveyStop at the end of leg i)
    dz_m: float = 0.0
    stop: SurveyStop | None = None


@dataclass
class Route:
    name: str
    legs: list[Leg]
    breaks: list[LegBreak]  # len(legs) - 1
    radius_m: float  # corridor corner radius
    lap_m: float = 0.0  # length of one corridor lap (for reference)
    tread_m: float = 0.28  # stair tread (one step per stair)
    gait_zones: list[tuple[float, float, str]] = field(default_factory=list)  # global (s_a, s_b, mode)
    marks: list[tuple[float, float, float]] = field(default_factory=list)  # reference points: (s_m, x_m, y_m)
    start_stop: SurveyStop | None = None  # survey at the start point (before leg 0)
    end_stop: SurveyStop | None = None  # survey at the end point (after the last leg)
    survey_points: np.ndarray | None = None  # (n, 3) x, y, floor of the stops, in survey order
    pauses: list[tuple[float, float]] = field(default_factory=list)  # the route's own: (s_m, duration_s)

    @property
    def leg_starts_m(self) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum([leg.length_m for leg in self.legs])])

    @property
    def length_m(self) -> float:
        return float(sum(leg.length_m for leg in self.legs))

    def gait_mode(self, s_m: float) -> str:
        """'stairs' on a flight, 'slow' around a staircase (approach, landing, exit), else 'walk'."""
        for s_a, s_b, mode in self.gait_zones:
            if mode == "stairs" and s_a <= s_m < s_b:
                return "stairs"
        for s_a, s_b, mode in self.gait_zones:
            if mode == "slow" and s_a <= s_m < s_b:
                return "slow"
        return "walk"

    def on_flight(self, s_m: np.ndarray) -> np.ndarray:
        s_m = np.asarray(s_m, float)
        out = np.zeros(s_m.shape, dtype=bool)
        for s_a, s_b, mode in self.gait_zones:
            if mode == "stairs":
                out |= (s_m >= s_a) & (s_m < s_b)
        return out


def _loop_points(world: World, start_xy, laps_needed: int):
    (x0, y0), (x1, _), (_, y1), _ = world.loop_corners_m.tolist()
    pts = [start_xy]
    for _ in range(laps_needed):
        pts += [(x1, y0), (x1, y1), (x0, y1), (x0, y0), start_xy]
    return pts


def loop_route(world: World, laps: float, radius_m: float) -> Route:
    """Laps of the floor-0 corridor loop, counter-clockwise from the world's start point."""
    start = tuple(world.start_xy_m)
    one = Polyline(_loop_points(world, start, 1), radius_m)
    path = Polyline(_loop_points(world, start, int(math.ceil(laps)) + 1), radius_m)
    leg = Leg(path=path, z0_m=0.0, length_m=laps * one.length_m)
    return Route(name="loop", legs=[leg], breaks=[], radius_m=radius_m, lap_m=one.length_m)


def tour_route(world: World, radius_m: float) -> Route:
    """The two-floor tour (see the module docstring); the building's layout comes from ``world``."""
    (x0, y0), (x1, _), (_, y1), _ = world.loop_corners_m.tolist()
    st = world.stairs
    el = world.elevator
    rs = STAIRWELL_RADIUS_M
    door_y = st.door_y_m
    f1a, f1b, f2a, f2b = st.flight1_start, st.flight1_end, st.flight2_start, st.flight2_end
    landing_y = st.landing_y_m
    lap0 = [(x0, world.tour_start_y_m), (x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    to_stairs = [
        (x0, door_y),
        (f1a[0], door_y, rs),
        f1a,
        f1b,
        (f1b[0], landing_y, rs),
        (f2a[0], landing_y, rs),
        f2a,
        f2b,
        (f2b[0], door_y, rs),
        (x0, door_y),
    ]
    lap1 = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, el.door_y_m), (el.x_m, el.door_y_m)]
    path1 = Polyline(lap0 + to_stairs + lap1, radius_m)
    # the flights run between waypoints 7-8 and 11-12 of path1
    i_f1 = len(lap0) + 2
    i_f2 = len(lap0) + 6
    v = path1.vertex_d
    flights = [
        Flight(float(v[i_f1]), float(v[i_f1 + 1]), st.flight_rise_m),
        Flight(float(v[i_f2]), float(v[i_f2 + 1]), world.storey_m - st.flight_rise_m),
    ]
    leg1 = Leg(path=path1, z0_m=0.0, flights=flights)
    path2 = Polyline(
        [(el.x_m, el.door_y_m), (x0, el.door_y_m), (x0, y0), (x1, y0), (x1, world.tour_end_y_m)], radius_m
    )
    leg2 = Leg(path=path2, z0_m=0.0)
    zones = []
    for f in flights:
        zones.append((f.d_a - 0.15, f.d_b, "stairs"))
    zones.append((flights[0].d_a - 2.2, flights[-1].d_b + 1.6, "slow"))
    lap = Polyline(_loop_points(world, (x0 + 4.0, y0), 1), radius_m).length_m
    return Route(
        name="tour",
        legs=[leg1, leg2],
        breaks=[LegBreak("elevator", dz_m=-leg1.z_end_m)],
        radius_m=radius_m,
        lap_m=lap,
        tread_m=st.tread_m,
        gait_zones=zones,
    )


def _project_on_straights(path: Polyline, x: float, y: float, tol_m: float = 1e-6) -> float:
    """Distance along ``path`` of a point lying on one of its straight pieces (ValueError otherwise)."""
    best = (math.inf, 0.0)
    for pc in path.pieces:
        if pc[0] != "L":
            continue
        _, d0, ln, x0, y0, h = pc
        e = (x - x0) * math.cos(h) + (y - y0) * math.sin(h)
        e_c = min(max(e, 0.0), ln)
        dist = math.hypot(x - (x0 + e_c * math.cos(h)), y - (y0 + e_c * math.sin(h)))
        if dist < best[0]:
            best = (dist, d0 + e_c)
    if best[0] > tol_m:
        raise ValueError(f"reference point ({x}, {y}) is not on a straight stretch of the track")
    return best[1]


def track_route(world: World, radius_m: float) -> Route:
    """The world's track (one leg), with its reference points as marks (in walking order)."""
    if world.track_m is None:
        raise ValueError(f"world {world.name!r} has no track")
    path = Polyline(world.track_m, radius_m)
    leg = Leg(path=path, z0_m=0.0)
    marks = []
    refs = world.reference_points_m if world.reference_points_m is not None else np.zeros((0, 2))
    for x, y in refs.tolist():
        marks.append((_project_on_straights(path, x, y), float(x), float(y)))
    if any(b[0] <= a[0] for a, b in zip(marks, marks[1:])):
        raise ValueError("reference points must be listed in walking order")
    return Route(name="track", legs=[leg], breaks=[], radius_m=radius_m, marks=marks)


def legs_route(world: World, radius_m: float) -> Route:
    """The world's walk as legs (``World.walk_legs``): flights rise along their stretch (the person
    slows from 2.2 m before a staircase's first flight to 1.6 m after its last, as on the tour), waits
    become pauses, and an elevator ride joins each leg to the next (to the next leg's floor level)."""
    if not world.walk_legs:
        raise ValueError(f"world {world.name!r} has no legs")
    legs, zones, pauses = [], [], []
    s0 = 0.0
    for spec in world.walk_legs:
        path = Polyline(spec.points, radius_m)
        v = path.vertex_d
        flights = [Flight(float(v[i]), float(v[i + 1]), rise) for i, rise in spec.flights]
        leg = Leg(path=path, z0_m=spec.floor * world.storey_m, flights=flights)
        for f in flights:
            zones.append((s0 + f.d_a - 0.15, s0 + f.d_b, "stairs"))
        if flights:
            zones.append((s0 + flights[0].d_a - 2.2, s0 + flights[-1].d_b + 1.6, "slow"))
        pauses += [(s0 + float(v[i]), float(sec)) for i, sec in spec.waits]
        legs.append(leg)
        s0 += leg.length_m
    breaks = [LegBreak("elevator", dz_m=nxt.z0_m - cur.z_end_m) for cur, nxt in zip(legs[:-1], legs[1:])]
    tread = world.stairs.tread_m if world.stairs is not None else 0.28
    return Route(
        name="legs",
        legs=legs,
        breaks=breaks,
        radius_m=radius_m,
        tread_m=tread,
        gait_zones=zones,
        pauses=pauses,
    )


def make_route(world: World, route: str, laps: float, radius_m: float) -> Route:
    if route == "loop":
        return loop_route(world, laps, radius_m)
    if route == "tour":
        return tour_route(world, radius_m)
    if route == "track":
        return track_route(world, radius_m)
    if route == "legs":
        return legs_route(world, radius_m)
    raise ValueError(f"unknown route {route!r}")
