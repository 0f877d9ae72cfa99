"""The built-in default world: a two-floor office, its walls, stairs, elevator, access points and
magnetic disturbances.

Model: a 60 m x 30 m floor plan, used for both floors (floor 0 and floor 1, ``STOREY_M`` = 3.5 m apart).
A rectangular corridor loop, 2 m wide, runs around a block of inner rooms; outer rooms sit between the
corridor and the exterior wall. Walls are line segments (used by the radio model to count crossed
walls), the same on every floor; door gaps are left where rooms open onto the corridor. The route
follows the corridor centre line (see ``route.py``).

Vertical links: the west outer room (x 0-7 m, y 10-20 m) is the stairwell, door at (7, 15): a dog-leg
staircase, flight 1 heading south along x = 4.8 m (10 risers of 0.175 m, 0.28 m treads), a landing at
y = 10.6 m, flight 2 heading north along x = 2.2 m (10 risers) up to floor 1. The elevator cab
(2.5 m x 2.5 m, centre (4.25, 22.5), door to the east) sits in the shaft of the north-west outer room,
door at (7, 22.5).

Access points: 16 per floor at the same plan positions (ceiling, 2.8 m above their floor), floor-1
BSSIDs differ from floor-0 ones in the 4th-from-last hex digit (…1x0 → …2x0).

Magnetic disturbances (``MagZone``): regions where steel perturbs the earth field — the elevator shaft
(both floors) and steel columns beside the corridor. Inside a zone of radius R at distance d from its
centre the local field is the earth field with its intensity multiplied by 1 + w·(gain − 1), its
azimuth turned by w·azimuth_deg and its inclination changed by w·dip_deg, with the weight
w = (1 − (d/R)²)² (1 at the centre, 0 from R on: outside every zone the field is undisturbed).

Survey geometry (``survey_points``): calibration points lie on a grid (``grid_origin_m`` + spacing ·
(i, j)) inside the world's walkable rectangles (``walkable_m``; for the office the 2 m corridor band),
at least a margin away from every wall and outside solid blocks (``blocked_m``: a concrete core, pillars);
or a world gives an explicit list (``survey_points_m``).

A second built-in world, ``aadr2015`` (``aadr2015_world``), replicates the experiment of Jäger, Süß and
Becker (a foyer, 8 access points, 67 calibration points on a 2 m grid, a ~70 m track with 14 reference
points): one floor, 20 m × 14 m (280 m²), open, with a concrete core (a lift and service shaft, 2 m × 6 m,
x 12-14 m, y 6-12 m; its walls attenuate 15 dB each, so the spot east of it, ``poor_coverage_m``, hears
most access points only through the core), two concrete pillars and a drywall cloakroom in the
north-west corner; a steel staircase next to the poor-coverage spot disturbs the magnetic field.
Walls may carry their own loss (``walls_loss_db``, NaN = the scenario's ``radio.wall_loss_db``).

Map frame: x east-ish, y north-ish, metres; heading counter-clockwise from +x [rad]. The map is rotated
from magnetic axes by ``map_rotation_deg``: the map frame is the magnetic east-north frame turned
counter-clockwise by that angle, so magnetic north lies along map heading ``90 deg - map_rotation_deg``.
Heights: metres above the floor-0 walking surface; floor f's surface is at f · STOREY_M.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .world_parts import LegSpec, Outline, SurveyPart
from .world_sources import Beacon, Door, GeoRef

FLOOR_W_M = 60.0
FLOOR_H_M = 30.0
# corridor centre line: rectangle corners (x_m, y_m), counter-clockwise, starting bottom-left
LOOP_X0_M, LOOP_X1_M = 8.0, 52.0
LOOP_Y0_M, LOOP_Y1_M = 5.0, 25.0
CORRIDOR_HALF_W_M = 1.0
STOREY_M = 3.5  # floor-to-floor height
N_FLOORS = 2


@dataclass(frozen=True)
class AccessPoint:
    bssid: int  # 48-bit MAC as an integer (aa:bb:cc:dd:ee:ff = 0xaabbccddeeff)
    channel: int  # 1..14 (2.4 GHz) or 36..165 (5 GHz)
    x_m: float
    y_m: float
    tx_power_dbm: float  # EIRP
    floor: int = 0

    @property
    def freq_mhz(self) -> int:
        if self.channel <= 14:
            return 2407 + 5 * self.channel if self.channel < 14 else 2484
        return 5000 + 5 * self.channel


@dataclass(frozen=True)
class Stairs:
    """A dog-leg staircase between floor 0 and floor 1 (plan coordinates, metres)."""

    door_y_m: float  # the stairwell door on the corridor's west wall
    flight1_start: tuple[float, float]
    flight1_end: tuple[float, float]
    landing_y_m: float  # centre line of the landing between the flights
    flight2_start: tuple[float, float]
    flight2_end: tuple[float, float]
    risers_per_flight: int = 10
    riser_m: float = 0.175
    tread_m: float = 0.28

    @property
    def flight_rise_m(self) -> float:
        return self.risers_per_flight * self.riser_m


@dataclass(frozen=True)
class Elevator:
    x_m: float  # cab centre
    door_y_m: float  # cab centre y = door y (the cab door faces east, onto the corridor)
    half_m: float = 1.25


@dataclass(frozen=True)
class MagZone:
    """A magnetic disturbance (see the module docstring)."""

    name: str
    x_m: float
    y_m: float
    radius_m: float
    floors: tuple[int, ...]
    gain: float  # field intensity factor at the centre
    azimuth_deg: float  # horizontal direction change at the centre (CCW)
    dip_deg: float  # inclination change at the centre (+ = steeper)

    def weight(self, x_m: np.ndarray, y_m: np.ndarray, floor: np.ndarray) -> np.ndarray:
        q = ((np.asarray(x_m) - self.x_m) ** 2 + (np.asarray(y_m) - self.y_m) ** 2) / self.radius_m**2
        w = np.where(q < 1.0, (1.0 - np.minimum(q, 1.0)) ** 2, 0.0)
        return np.where(np.isin(floor, self.floors), w, 0.0)


@dataclass(frozen=True)
class World:
    name: str
    floor_w_m: float
    floor_h_m: float
    walls_m: np.ndarray  # (n_wall, 4): x0, y0, x1, y1 — the plan of every floor
    aps: tuple[AccessPoint, ...]
    loop_corners_m: np.ndarray  # (4, 2) corridor centre-line rectangle, counter-clockwise
    start_xy_m: tuple[float, float]  # start of the ``loop`` route (bottom straight)
    map_rotation_deg: float = 20.0
    ground_z_m: float = 0.0  # height of floor 0 above the pressure reference [m]
    n_floors: int = N_FLOORS
    storey_m: float = STOREY_M
    stairs: Stairs | None = None
    elevator: Elevator | None = None
    mag_zones: tuple[MagZone, ...] = ()
    tour_start_y_m: float = 13.0  # the ``tour`` route starts at (loop x0, this), heading south
    tour_end_y_m: float = 15.0  # and ends at (loop x1, this)
    extra: dict = field(default_factory=dict)
    walls_loss_db: np.ndarray | None = None  # (n_wall,) own loss per wall [dB]; NaN/None = radio.wall_loss_db
    walkable_m: np.ndarray | None = None  # (k, 4) x0, y0, x1, y1: where calibration points may lie
    blocked_m: np.ndarray | None = None  # (k, 4) solid blocks (no calibration point inside)
    grid_origin_m: tuple[float, float] = (0.0, 0.0)  # the survey grid passes through this point
    survey_points_m: np.ndarray | None = None  # (n, 3) x, y, floor: the world's own calibration points
    track_m: tuple | None = None  # waypoints of the ``track`` route (starts at the first)
    reference_points_m: np.ndarray | None = None  # (n, 2) surveyed reference points on the track
    poor_coverage_m: tuple | None = None  # (x0, y0, x1, y1) the spot of poor Wi-Fi coverage
    description: str = ""
    # sources beyond Wi-Fi (world_sources.py): None/() = none (no GNSS, BLE or landmark frames)
    geo: GeoRef | None = None  # the map frame on WGS-84 (the building description's [geo])
    beacons: tuple[Beacon, ...] = ()
    doors: tuple[Door, ...] = ()  # doors to the outside (with their NFC landmark tags)
    footprint_m: np.ndarray | None = None  # (k, 4) the building's inside; None = all indoors
    # several buildings (world_parts.py): () / None = one building as before
    outlines: tuple[Outline, ...] = ()  # the buildings: name, footprint rectangle, floors
    walk_legs: tuple[LegSpec, ...] = ()  # the ``legs`` route
    survey_parts: tuple[SurveyPart, ...] | None = None  # the survey's parts, in walking order

    @property
    def area_m2(self) -> float:
        return self.floor_w_m * self.floor_h_m


def _point_segment_distance(p: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """(n,) distance of each point (n, 2) to the nearest wall segment."""
    if len(walls) == 0:
        return np.full(len(p), np.inf)
    a, b = walls[None, :, 0:2], walls[None, :, 2:4]
    ab = b - a
    q = p[:, None, :]
    u = np.clip(np.sum((q - a) * ab, axis=-1) / np.maximum(np.sum(ab * ab, axis=-1), 1e-12), 0.0, 1.0)
    d = np.hypot(*(q - (a + u[..., None] * ab)).transpose(2, 0, 1))
    return d.min(axis=1)


def survey_points(
    world: World, spacing_m: float, margin_m: float, floors, layout: str = "grid"
) -> np.ndarray:
    """Calibration points (n, 3: x, y, floor) of ``floors``: the world's own list (``layout`` "world") or a
    grid of ``spacing_m`` through ``grid_origin_m``, inside a walkable rectangle shrunk by ``margin_m``, at
    least ``margin_m`` from every wall and outside every solid block grown by ``margin_m``. Ordered by
    floor, then y, then x."""
    floors = list(floors)
    if layout == "world":
        if world.survey_points_m is None:
            raise ValueError(
                f"world {world.name!r} has no calibration point list (use survey.layout = 'grid')"
            )
        pts = np.asarray(world.survey_points_m, float)
        pts = pts[np.isin(pts[:, 2], floors)]
    else:
        ox, oy = world.grid_origin_m
        xs = ox + spacing_m * np.arange(
            math.floor(-ox / spacing_m), math.ceil((world.floor_w_m - ox) / spacing_m) + 1
        )
        ys = oy + spacing_m * np.arange(
            math.floor(-oy / spacing_m), math.ceil((world.floor_h_m - oy) / spacing_m) + 1
        )
        gx, gy = np.meshgrid(np.round(xs, 9), np.round(ys, 9))
        xy = np.stack([gx.ravel(), gy.ravel()], axis=1)
        walk = (
            world.walkable_m
            if world.walkable_m is not None
            else np.array([[0.0, 0.0, world.floor_w_m, world.floor_h_m]])
        )
        inside = np.zeros(len(xy), bool)
        for x0, y0, x1, y1 in walk:
            inside |= (
                (xy[:, 0] >= x0 + margin_m - 1e-9)
                & (xy[:, 0] <= x1 - margin_m + 1e-9)
                & (xy[:, 1] >= y0 + margin_m - 1e-9)
                & (xy[:, 1] <= y1 - margin_m + 1e-9)
            )
        for x0, y0, x1, y1 in world.blocked_m if world.blocked_m is not None else []:
            inside &= ~(
                (xy[:, 0] > x0 - margin_m)
                & (xy[:, 0] < x1 + margin_m)
                & (xy[:, 1] > y0 - margin_m)
                & (xy[:, 1] < y1 + margin_m)
            )
        inside &= _point_segment_distance(xy, world.walls_m) >= margin_m - 1e-9
        xy = xy[inside]
        pts = (
            np.concatenate([np.column_stack([xy, np.full(len(xy), f, float)]) for f in floors])
            if floors
            else np.zeros((0, 3))
        )
    order = np.lexsort((pts[:, 0], pts[:, 1], pts[:, 2]))
    return pts[order]


def _rect(x0: float, y0: float, x1: float, y1: float, doors=()) -> list:
    """Walls of an axis-aligned rectangle; ``doors`` = [(side, centre_m, width_m)], side in bottom/top/left/right."""
    sides = {
        "bottom": ((x0, y0), (x1, y0)),
        "top": ((x0, y1), (x1, y1)),
        "left": ((x0, y0), (x0, y1)),
        "right": ((x1, y0), (x1, y1)),
    }
    walls = []
    for name, (a, b) in sides.items():
        horiz = a[1] == b[1]
        lo, hi = (a[0], b[0]) if horiz else (a[1], b[1])
        cur = lo
        pieces = []
        for g0, g1 in sorted((c - w / 2, c + w / 2) for s, c, w in doors if s == name):
            if g0 > cur:
                pieces.append((cur, g0))
            cur = max(cur, g1)
        if cur < hi:
            pieces.append((cur, hi))
        for u0, u1 in pieces:
            walls.append((u0, a[1], u1, a[1]) if horiz else (a[0], u0, a[0], u1))
    return walls


def _default_walls() -> np.ndarray:
    w = []
    # exterior wall
    w += list(_rect(0.0, 0.0, FLOOR_W_M, FLOOR_H_M))
    # corridor walls (outer and inner edge of the loop), with doors to the rooms
    ox0, oy0 = LOOP_X0_M - CORRIDOR_HALF_W_M, LOOP_Y0_M - CORRIDOR_HALF_W_M
    ox1, oy1 = LOOP_X1_M + CORRIDOR_HALF_W_M, LOOP_Y1_M + CORRIDOR_HALF_W_M
    ix0, iy0 = LOOP_X0_M + CORRIDOR_HALF_W_M, LOOP_Y0_M + CORRIDOR_HALF_W_M
    ix1, iy1 = LOOP_X1_M - CORRIDOR_HALF_W_M, LOOP_Y1_M - CORRIDOR_HALF_W_M
    outer_doors = (
        [("bottom", x, 1.0) for x in (14.0, 26.0, 38.0, 48.0)]
        + [("top", x, 1.0) for x in (12.0, 24.0, 36.0, 46.0)]
        + [("left", 15.0, 1.2), ("left", 22.5, 1.2), ("right", 15.0, 1.0)]
    )
    inner_doors = [("bottom", x, 1.0) for x in (13.0, 21.0, 29.0, 37.0, 45.0)] + [
        ("top", x, 1.0) for x in (13.0, 21.0, 29.0, 37.0, 45.0)
    ]
    w += list(_rect(ox0, oy0, ox1, oy1, outer_doors))
    w += list(_rect(ix0, iy0, ix1, iy1, inner_doors))
    # inner rooms: a spine wall and partitions every 8 m
    w.append((ix0, 15.0, ix1, 15.0))
    for x in np.arange(ix0 + 8.0, ix1 - 1.0, 8.0):
        w.append((float(x), iy0, float(x), iy1))
    # outer rooms: partitions from the corridor to the exterior wall
    for x in (10.0, 20.0, 32.0, 44.0):
        w.append((x, 0.0, x, oy0))
        w.append((x, oy1, x, FLOOR_H_M))
    for y in (10.0, 20.0):
        w.append((0.0, y, ox0, y))
        w.append((ox1, y, FLOOR_W_M, y))
    # stairwell: the wall between the two flights
    w.append((3.5, 11.2, 3.5, 14.5))
    # elevator shaft around the cab, door east
    w += list(_rect(3.0, 21.25, 5.5, 23.75, [("right", 22.5, 1.0)]))
    return np.asarray(w, dtype=float)


def _default_aps() -> tuple[AccessPoint, ...]:
    # (x_m, y_m, channel, tx_power_dbm); BSSIDs share a vendor OUI, last octets differ
    spec = [
        (5.0, 3.0, 1, 18.0),
        (16.0, 2.0, 6, 17.0),
        (27.0, 2.5, 11, 18.0),
        (40.0, 2.0, 36, 20.0),
        (55.0, 3.0, 6, 17.0),
        (57.0, 15.0, 44, 20.0),
        (55.0, 27.0, 1, 18.0),
        (40.0, 28.0, 149, 20.0),
        (26.0, 27.5, 6, 17.0),
        (14.0, 28.0, 11, 18.0),
        (3.0, 26.0, 40, 20.0),
        (3.0, 14.0, 6, 16.0),
        (17.0, 11.0, 1, 15.0),
        (33.0, 19.0, 11, 15.0),
        (45.0, 10.0, 48, 18.0),
        (30.0, 5.0, 157, 20.0),
    ]
    return tuple(
        ap
        for floor in range(N_FLOORS)
        for ap in aps_from_spec(spec, 0x3C_84_6A_00_10_00 + (floor << 12), floor)
    )


def aps_from_spec(
    spec: list[tuple[float, float, int, float]], base_bssid: int, floor: int = 0
) -> tuple[AccessPoint, ...]:
    """Access points from rows (x_m, y_m, channel, tx_power_dbm) on one floor: the i-th BSSID is
    base + 16·i, +1 on a 5 GHz channel (> 14), so every world numbers its APs the same way."""
    return tuple(
        AccessPoint(
            bssid=base_bssid + (i << 4) + (1 if ch > 14 else 0),
            channel=ch,
            x_m=x,
            y_m=y,
            tx_power_dbm=p,
            floor=floor,
        )
        for i, (x, y, ch, p) in enumerate(spec)
    )


def _default_mag_zones() -> tuple[MagZone, ...]:
    return (
        MagZone("elevator shaft", 4.25, 22.5, 3.0, (0, 1), gain=1.45, azimuth_deg=40.0, dip_deg=-15.0),
        MagZone("steel column south", 30.0, 6.0, 2.0, (0,), gain=0.6, azimuth_deg=-35.0, dip_deg=10.0),
        MagZone("steel column west", 7.0, 9.0, 2.0, (0,), gain=1.3, azimuth_deg=-25.0, dip_deg=8.0),
        MagZone("steel column east", 53.0, 12.0, 2.0, (1,), gain=1.35, azimuth_deg=30.0, dip_deg=-10.0),
    )


def _corridor_band() -> np.ndarray:
    """The office's walkable corridor: four 2 m wide rectangles around the loop's centre line."""
    h = CORRIDOR_HALF_W_M
    return np.array(
        [
            [LOOP_X0_M - h, LOOP_Y0_M - h, LOOP_X1_M + h, LOOP_Y0_M + h],
            [LOOP_X0_M - h, LOOP_Y1_M - h, LOOP_X1_M + h, LOOP_Y1_M + h],
            [LOOP_X0_M - h, LOOP_Y0_M - h, LOOP_X0_M + h, LOOP_Y1_M + h],
            [LOOP_X1_M - h, LOOP_Y0_M - h, LOOP_X1_M + h, LOOP_Y1_M + h],
        ]
    )


def default_world(map_rotation_deg: float = 20.0) -> World:
    corners = np.array(
        [[LOOP_X0_M, LOOP_Y0_M], [LOOP_X1_M, LOOP_Y0_M], [LOOP_X1_M, LOOP_Y1_M], [LOOP_X0_M, LOOP_Y1_M]]
    )
    stairs = Stairs(
        door_y_m=15.0,
        flight1_start=(4.8, 14.0),
        flight1_end=(4.8, 11.2),
        landing_y_m=10.6,
        flight2_start=(2.2, 11.2),
        flight2_end=(2.2, 14.0),
    )
    return World(
        name="default",
        floor_w_m=FLOOR_W_M,
        floor_h_m=FLOOR_H_M,
        walls_m=_default_walls(),
        aps=_default_aps(),
        loop_corners_m=corners,
        start_xy_m=(12.0, LOOP_Y0_M),
        map_rotation_deg=map_rotation_deg,
        stairs=stairs,
        elevator=Elevator(x_m=4.25, door_y_m=22.5),
        mag_zones=_default_mag_zones(),
        walkable_m=_corridor_band(),
        grid_origin_m=(LOOP_X0_M, LOOP_Y0_M),
        description="two-floor office, 60 m x 30 m, corridor loop, stairs and elevator",
    )
