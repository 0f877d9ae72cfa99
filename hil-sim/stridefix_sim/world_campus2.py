"""The ``campus2`` world: two buildings joined by an outdoor path, for the multi-scheme controller
(Jäger, Süß, Becker §III: contexts outdoor / building / floor, ports door / stairs / elevator).

A new world rather than an extension of ``campus``: the existing worlds' walks, surveys and radio maps
stay as they are. The world has one plan for every floor (world.py); the outlines (world_parts.py) say
which building has which floors, so the building description gives each wall only its building's
floors.

Building **A** (map frame, metres): footprint x 0–32, y 0–24, floors 0, 1, 2 (``STOREY_M`` 3.5 m apart),
the same plan on each. A corridor loop (2 m wide, centre line x 8–26, y 4–20) round an inner block of
four rooms (spine y = 12, partition x = 17, doors at x 13 and 21 on both long sides); rooms between the
corridor and the exterior wall. West of the corridor: the stairwell (x 0–7, y 7–14, door at (7, 12)) —
a dog-leg staircase between floors 0 and 1, flight 1 south along x = 4.8 m from y 11.0 to 8.2 (10
risers of 0.175 m, 0.28 m treads), a landing at y = 7.6 m, flight 2 north along x = 2.2 m from y 8.2 to
11.0: 20 steps end to end, from (4.8, 11.0) on floor 0 to (2.2, 11.0) on floor 1 — and the elevator
(cab 2.5 m × 2.5 m centred (4.25, 17.5), its door east, in a room x 0–7, y 14–21 with its door at
(7, 17.5)) serving floors 0, 1, 2. East of the corridor the lobby (x 27–32, y 9–15, an opening 2.4 m
wide at (27, 12)) and the door to the outside ``A-door`` at (32, 12), 1.6 m wide, NFC tag landmark 1.
Wi-Fi: 8 APs per floor on the ceiling (BSSIDs 3c:84:6a:00:5x:x0 on floor 0, …6x:x0 on 1, …7x:x0 on 2);
floors attenuate ``radio.floor_loss_db`` each. No BLE beacon.

Building **B**: footprint x 90–114, y 4–20, floor 0 only. A corridor y 11–13 from the door
``B-door`` at (90, 12) (1.6 m, NFC tag landmark 2) to the east wall, three rooms north (x 90–98,
98–106, 106–114, doors at x 94, 102, 110 on y = 13) and three south (doors on y = 11). 10 BLE beacons
on the walls (02:00:00:00:01:01 … 0a, measured power −56 … −62 dBm at 1 m, 5 Hz); no Wi-Fi AP.

Outdoors (GNSS, outside both footprints): the path from A's door east to (38, 12), south-east to
(46, 4), east to (76, 4), north-east to (84, 12) and east to B's door: 64.6 m.

Walk (route ``legs``, ≈ 390 m): outdoors from (50, 22) south and west to A's door (28 m), floor 0
along the south corridor to the stairwell, up the stairs to floor 1, a lap of floor 1 to the elevator
door (waiting 10 s for the cab), the ride to floor 2, a lap of floor 2 back to the elevator (waiting
14 s), the ride down to floor 0, along the north corridor and out of A's door, the outdoor path, in
through B's door, along B's corridor and into its north-east room, ending at (110, 16).

Survey (layout ``world``, parts): B first (its corridor and north-east room, BLE heard throughout),
then out of B's door and along the path into A, A's floor 0 (corridor loop and lobby), the elevator to
floor 1, then 2; calibration points on the 2 m grid through (8, 4), 0.5 m or more from every wall.
"""

from __future__ import annotations

import numpy as np

from .world import STOREY_M, AccessPoint, Elevator, MagZone, Stairs, World, _rect, aps_from_spec
from .world_campus import _line_x
from .world_parts import LegSpec, Outline, SurveyPart
from .world_sources import Beacon, Door, GeoRef

A_RECT = (0.0, 0.0, 32.0, 24.0)
B_RECT = (90.0, 4.5, 114.0, 20.5)
A_FLOORS = (0, 1, 2)
LOOP_X_M, LOOP_Y_M = (8.0, 26.0), (4.0, 20.0)  # A's corridor centre line
B_CORRIDOR_Y_M = (11.5, 13.5)
DOORS = (
    Door("A-door", 32.0, 12.0, 1.6, floor=0, landmark_id=1),
    Door("B-door", 90.0, 12.5, 1.6, floor=0, landmark_id=2),
)
STAIRS = Stairs(
    door_y_m=12.0,
    flight1_start=(4.8, 11.0),
    flight1_end=(4.8, 8.2),
    landing_y_m=7.6,
    flight2_start=(2.2, 8.2),
    flight2_end=(2.2, 11.0),
)
ELEVATOR = Elevator(x_m=4.25, door_y_m=17.5)
ELEVATOR_WAIT_XY_M = (6.3, 17.5)  # in front of the elevator room, outside the cab's port
# the outdoor path from A's door to B's door
PATH_M = ((32.0, 12.0), (38.0, 12.0), (46.0, 4.0), (76.0, 4.0), (84.0, 12.5), (90.0, 12.5))
WAIT_FLOOR1_S, WAIT_FLOOR2_S = 10.0, 14.0  # waiting at the elevator door for the cab


def _walls() -> np.ndarray:
    w = list(_rect(*A_RECT, [("right", 12.0, 1.6)]))  # A's exterior, its door
    (x0, x1), (y0, y1) = LOOP_X_M, LOOP_Y_M
    outer = [("left", 12.0, 1.2), ("left", 17.5, 1.2), ("left", 5.0, 1.0), ("right", 12.0, 2.4)]
    outer += [(side, x, 1.0) for side in ("bottom", "top") for x in (12.0, 20.0)]
    w += _rect(x0 - 1.0, y0 - 1.0, x1 + 1.0, y1 + 1.0, outer)  # corridor, outer edge
    inner = [(side, x, 1.0) for side in ("bottom", "top") for x in (13.0, 21.0)]
    w += _rect(x0 + 1.0, y0 + 1.0, x1 - 1.0, y1 - 1.0, inner)  # corridor, inner edge
    w += [(9.0, 11.5, 25.0, 11.5), (17.0, 5.0, 17.0, 19.0)]  # inner block: spine, partition
    w += [(0.0, 7.0, 7.0, 7.0), (0.0, 14.5, 7.0, 14.5), (0.0, 21.0, 7.0, 21.0)]  # west rooms
    w += [(16.0, 0.0, 16.0, 3.0), (16.0, 21.0, 16.0, 24.0)]  # south and north strips
    w += [(27.0, 9.0, 32.0, 9.0), (27.0, 15.0, 32.0, 15.0)]  # the lobby's sides
    w.append((3.5, 8.2, 3.5, 11.5))  # stairwell: between the flights
    w += _rect(3.0, 16.25, 5.5, 18.75, [("right", 17.5, 1.0)])  # elevator shaft, door east
    bx0, by0, bx1, by1 = B_RECT
    w += _rect(*B_RECT, [("left", 12.5, 1.6)])  # B's exterior, its door
    ys, yn = B_CORRIDOR_Y_M
    rooms = [(x, 1.0) for x in (94.0, 102.0, 110.0)]
    w += _line_x(bx0, bx1, yn, rooms) + _line_x(bx0, bx1, ys, rooms)
    for x in (98.0, 106.0):
        w += [(x, yn, x, by1), (x, by0, x, ys)]
    return np.asarray(w, float)


def _aps() -> tuple[AccessPoint, ...]:
    spec = [
        (4.0, 2.0, 1, 18.0),
        (16.0, 1.5, 36, 20.0),
        (29.0, 5.0, 11, 18.0),
        (30.0, 20.0, 6, 17.0),
        (16.0, 22.5, 44, 20.0),
        (3.0, 22.5, 1, 17.0),
        (13.0, 8.0, 6, 15.0),
        (21.0, 16.0, 149, 18.0),
    ]
    return tuple(ap for f in A_FLOORS for ap in aps_from_spec(spec, 0x3C_84_6A_00_50_00 + (f << 12), f))


def _beacons() -> tuple[Beacon, ...]:
    spec = [
        (92.0, 20.3, -59.0),
        (102.0, 20.3, -61.0),
        (112.0, 20.3, -58.0),
        (113.8, 16.5, -60.0),
        (113.8, 8.5, -62.0),
        (112.0, 4.7, -57.0),
        (102.0, 4.7, -59.0),
        (92.0, 4.7, -56.0),
        (98.0, 13.4, -60.0),
        (106.0, 11.6, -58.0),
    ]
    return tuple(
        Beacon(mac=0x02_00_00_00_01_00 + i + 1, x_m=x, y_m=y, rssi_1m_dbm=p)
        for i, (x, y, p) in enumerate(spec)
    )


def _survey_points() -> np.ndarray:
    (x0, x1), (y0, y1) = LOOP_X_M, LOOP_Y_M
    xs, ys = np.arange(x0, x1 + 1e-9, 2.0), np.arange(y0 + 2.0, y1 - 2.0 + 1e-9, 2.0)
    loop = [(x, y) for y in (y0, y1) for x in xs] + [(x, y) for x in (x0, x1) for y in ys]
    lobby = [(x, y) for x in (28.0, 30.0) for y in (10.0, 12.0, 14.0)]
    a = [(x, y, float(f)) for f in A_FLOORS for x, y in loop + lobby]
    b = [(x, 12.5, 0.0) for x in np.arange(92.0, 112.0 + 1e-9, 2.0)]
    b += [(x, y, 0.0) for x in (108.0, 110.0, 112.0) for y in (14.5, 16.5, 18.5)]
    return np.asarray(a + b, float)


def _legs() -> tuple[LegSpec, ...]:
    (x0, x1), (y0, y1) = LOOP_X_M, LOOP_Y_M
    st, el, rs = STAIRS, ELEVATOR, 0.6
    cab, wait = (el.x_m, el.door_y_m), ELEVATOR_WAIT_XY_M
    stairs = [
        (x0, st.door_y_m),
        (st.flight1_start[0], st.door_y_m, rs),
        st.flight1_start,
        st.flight1_end,
        (st.flight1_end[0], st.landing_y_m, rs),
        (st.flight2_start[0], st.landing_y_m, rs),
        st.flight2_start,
        st.flight2_end,
        (st.flight2_end[0], st.door_y_m, rs),
        (x0, st.door_y_m),
    ]
    lap_to_cab = [(x0, y1), (x1, y1), (x1, y0), (x0, y0), (x0, el.door_y_m), wait, cab]
    leg1 = [(50.0, 22.0), (50.0, 12.0), (x1, 12.0), (x1, y0), (x0, y0)] + stairs + lap_to_cab
    i1 = 5 + 2  # the flights start at the stairs' 3rd and 7th waypoints
    rise = st.flight_rise_m
    leg2 = [cab, (x0, el.door_y_m)] + lap_to_cab
    leg3 = [cab, (x0, el.door_y_m), (x0, y1), (x1, y1), (x1, 12.0)] + list(PATH_M)
    leg3 += [(110.0, 12.5), (110.0, 16.5)]
    return (
        LegSpec(
            tuple(leg1),
            0,
            flights=((i1, rise), (i1 + 4, STOREY_M - rise)),
            waits=((len(leg1) - 2, WAIT_FLOOR1_S),),
        ),
        LegSpec(tuple(leg2), 2, waits=((len(leg2) - 2, WAIT_FLOOR2_S),)),
        LegSpec(tuple(leg3), 0),
    )


def campus2_world(map_rotation_deg: float = 20.0) -> World:
    (x0, x1), (y0, y1) = LOOP_X_M, LOOP_Y_M
    outlines = (Outline("A", A_RECT, A_FLOORS), Outline("B", B_RECT, (0,)))
    via = tuple(reversed(PATH_M))  # from B's door back to A's
    return World(
        name="campus2",
        floor_w_m=B_RECT[2],
        floor_h_m=A_RECT[3],
        walls_m=_walls(),
        aps=_aps(),
        loop_corners_m=np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]),
        start_xy_m=(112.0, 18.5),  # the survey starts in B's north-east room
        map_rotation_deg=map_rotation_deg,
        n_floors=len(A_FLOORS),
        stairs=STAIRS,
        elevator=ELEVATOR,
        mag_zones=(
            MagZone("elevator shaft", ELEVATOR.x_m, ELEVATOR.door_y_m, 3.0, A_FLOORS, 1.45, 40.0, -15.0),
        ),
        grid_origin_m=(x0, y0),
        survey_points_m=_survey_points(),
        description="campus2: building A 32 m x 24 m, 3 floors, Wi-Fi, stairs 0-1, elevator 0-2; building B "
        "24 m x 16 m, 1 floor, 10 BLE beacons; 64.6 m outdoor path with GNSS; doors with NFC tags",
        geo=GeoRef(rotation_deg=map_rotation_deg),
        beacons=_beacons(),
        doors=DOORS,
        footprint_m=np.array([A_RECT, B_RECT]),
        outlines=outlines,
        walk_legs=_legs(),
        survey_parts=(
            SurveyPart(0, B_RECT),
            SurveyPart(0, A_RECT, via_m=via),
            SurveyPart(1, A_RECT),
            SurveyPart(2, A_RECT),
        ),
    )
