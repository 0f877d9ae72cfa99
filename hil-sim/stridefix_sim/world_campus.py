"""The ``campus`` world: a one-floor building (40 m × 20 m) with two doors to the outside, BLE
beacons, NFC tags at the doors, and the open ground around it where GNSS works.

A new world rather than an extension of the default office: the office's walk, radio map and
change-indication replays stay as they are, and this world is built for what the office lacks (an
outdoor stretch through doors, a geo-reference, beacons).

Building (map frame, metres; floor 0 only): footprint x 0–40, y 0–20 (``footprint_m``); a corridor
along y 9–11 from the west door (0, 10) to the east wall; four rooms north of it (x 0–10, 10–20, 20–30,
30–40, doors 1 m wide at x 5, 15, 25, 35 on y = 11); south of it three rooms (x 0–10, 10–20, 20–26,
doors at x 5, 15, 23 on y = 9), a lobby x 26–34 (opening 2.4 m wide at x 30 on y = 9) and a room
x 34–40 (door at x 37). Doors to the outside, 1.6 m wide, each with an NFC tag at its centre: ``west``
(0, 10), landmark 1, and ``south`` (30, 0), landmark 2, into the lobby. Walls attenuate
``radio.wall_loss_db`` each (the exterior wall too).

Radio: 8 Wi-Fi APs on the ceiling inside (BSSIDs 3c:84:6a:00:3x:x0), 10 BLE beacons on the walls
(02:00:00:00:00:01 … 0a, measured power −56 … −62 dBm at 1 m, 5 Hz), all indoors.

Track (route ``track``, ≈ 138 m): from the north-east room (35, 16) into the corridor, west along it
and out of the west door (landmark 1), outdoors 5 m west, 18 m south, 35 m east and 8 m north (66 m
outside), in through the south door (landmark 2), the lobby, the corridor west and into the second
north room, ending at (15, 16). Calibration points (survey): the 2 m grid through (1, 10) in the
corridor, the lobby and the two north rooms the track visits.
"""

from __future__ import annotations

import numpy as np

from .world import AccessPoint, World, _rect, aps_from_spec
from .world_sources import Beacon, Door, GeoRef

CAMPUS_W_M, CAMPUS_H_M = 40.0, 20.0
CORRIDOR_Y_M = (9.0, 11.0)
CAMPUS_DOORS = (
    Door("west", 0.0, 10.0, 1.6, floor=0, landmark_id=1),
    Door("south", 30.0, 0.0, 1.6, floor=0, landmark_id=2),
)
CAMPUS_TRACK_M = (
    (35.0, 16.0),
    (35.0, 10.0),
    (-5.0, 10.0),
    (-5.0, -8.0),
    (30.0, -8.0),
    (30.0, 10.0),
    (15.0, 10.0),
    (15.0, 16.0),
)


def _line_x(x0: float, x1: float, y: float, doors) -> list:
    """A wall along y from x0 to x1 with door gaps [(centre_x, width)]."""
    out, cur = [], x0
    for g0, g1 in sorted((c - w / 2, c + w / 2) for c, w in doors):
        if g0 > cur:
            out.append((cur, y, g0, y))
        cur = max(cur, g1)
    if cur < x1:
        out.append((cur, y, x1, y))
    return out


def _campus_walls() -> np.ndarray:
    w = list(
        _rect(0.0, 0.0, CAMPUS_W_M, CAMPUS_H_M, [("left", 10.0, 1.6), ("bottom", 30.0, 1.6)])
    )  # exterior wall, the two doors
    y_s, y_n = CORRIDOR_Y_M
    w += _line_x(0.0, CAMPUS_W_M, y_n, [(x, 1.0) for x in (5.0, 15.0, 25.0, 35.0)])
    w += _line_x(0.0, CAMPUS_W_M, y_s, [(5.0, 1.0), (15.0, 1.0), (23.0, 1.0), (30.0, 2.4), (37.0, 1.0)])
    for x in (10.0, 20.0, 30.0):  # north rooms
        w.append((x, y_n, x, CAMPUS_H_M))
    for x in (10.0, 20.0, 26.0, 34.0):  # south rooms and the lobby's sides
        w.append((x, 0.0, x, y_s))
    return np.asarray(w, float)


def _campus_aps() -> tuple[AccessPoint, ...]:
    spec = [
        (4.0, 15.0, 1, 18.0),
        (16.0, 17.0, 36, 20.0),
        (26.0, 14.0, 6, 17.0),
        (37.0, 17.0, 11, 18.0),
        (5.0, 4.0, 44, 20.0),
        (16.0, 5.0, 6, 17.0),
        (30.0, 5.0, 1, 18.0),
        (37.0, 4.0, 149, 20.0),
    ]
    return aps_from_spec(spec, 0x3C_84_6A_00_30_00)


def _campus_beacons() -> tuple[Beacon, ...]:
    spec = [
        (5.0, 19.8, -59.0),
        (18.0, 19.8, -61.0),
        (28.0, 19.8, -58.0),
        (39.8, 15.0, -60.0),
        (0.2, 3.0, -62.0),
        (15.0, 0.2, -57.0),
        (30.0, 8.0, -59.0),
        (39.8, 3.0, -56.0),
        (10.0, 10.9, -60.0),
        (30.0, 10.9, -58.0),
    ]
    return tuple(
        Beacon(mac=0x02_00_00_00_00_00 + i + 1, x_m=x, y_m=y, rssi_1m_dbm=p)
        for i, (x, y, p) in enumerate(spec)
    )


def campus_world(map_rotation_deg: float = 20.0) -> World:
    y_s, y_n = CORRIDOR_Y_M
    walkable = [
        (0.0, y_s, CAMPUS_W_M, y_n),  # corridor
        (26.0, 0.0, 34.0, y_s),  # lobby
        (10.0, y_n, 20.0, CAMPUS_H_M),  # north room 2 (the track ends there)
        (30.0, y_n, 40.0, CAMPUS_H_M),  # north room 4 (the track starts there)
    ]
    return World(
        name="campus",
        floor_w_m=CAMPUS_W_M,
        floor_h_m=CAMPUS_H_M,
        walls_m=_campus_walls(),
        aps=_campus_aps(),
        loop_corners_m=np.array([[-5.0, -8.0], [45.0, -8.0], [45.0, 25.0], [-5.0, 25.0]]),
        start_xy_m=(0.0, -8.0),
        map_rotation_deg=map_rotation_deg,
        n_floors=1,
        walkable_m=np.asarray(walkable, float),
        grid_origin_m=(1.0, 10.0),
        track_m=CAMPUS_TRACK_M,
        description="campus: 40 m x 20 m one-floor building, 2 doors with NFC tags, 10 BLE beacons, "
        "outdoor stretch with GNSS",
        geo=GeoRef(rotation_deg=map_rotation_deg),
        beacons=_campus_beacons(),
        doors=CAMPUS_DOORS,
        footprint_m=np.array([[0.0, 0.0, CAMPUS_W_M, CAMPUS_H_M]]),
    )
