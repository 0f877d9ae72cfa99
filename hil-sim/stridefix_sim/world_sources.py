"""What a world offers besides walls and Wi-Fi: its geo-reference, BLE beacons, doors to the outside
with their NFC landmark tags, and the building footprint that tells indoors from outdoors.

Geo-reference (``GeoRef``): the map frame's origin on WGS-84 (latitude, longitude, altitude of the
floor-0 walking surface) and its rotation: the map frame is the local east-north frame turned
counter-clockwise by ``rotation_deg``, so a map vector (x, y) is east-north
``(x·cos θ − y·sin θ, x·sin θ + y·cos θ)``. Latitude/longitude come from the local tangent plane with the
WGS-84 radii of curvature at the origin (:func:`stridefix_common.geodesy.unproject`, the inverse of
the analyzer's projection; the firmware's sf_geo uses the same plane). The
simulator has no magnetic declination, so a world's geo rotation equals its ``map_rotation_deg``.

Beacons (``Beacon``): a BLE advertiser at (x, y) on a floor, ``z_m`` above that floor's surface, with
its measured power (RSSI at 1 m, as iBeacon's ``txPower`` byte reports it) and an advertising interval.

Doors (``Door``): a gap in the exterior wall at (x, y), ``width_m`` wide, on a floor; an NFC tag
(a landmark, id ``landmark_id``) sits at its centre. ``footprint_m`` of a world: axis-aligned rectangles
(x0, y0, x1, y1) whose union is the building's inside; None = everything is indoors (no GNSS).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from stridefix_common.geodesy import unproject


@dataclass(frozen=True)
class GeoRef:
    origin_lat_deg: float = 47.3769
    origin_lon_deg: float = 8.5417
    origin_alt_m: float = 408.0
    rotation_deg: float = 20.0

    def map_to_en(self, x_m, y_m) -> tuple[np.ndarray, np.ndarray]:
        th = math.radians(self.rotation_deg)
        x, y = np.asarray(x_m, float), np.asarray(y_m, float)
        return x * math.cos(th) - y * math.sin(th), x * math.sin(th) + y * math.cos(th)

    def en_to_map(self, e_m, n_m) -> tuple[np.ndarray, np.ndarray]:
        th = math.radians(self.rotation_deg)
        e, n = np.asarray(e_m, float), np.asarray(n_m, float)
        return e * math.cos(th) + n * math.sin(th), -e * math.sin(th) + n * math.cos(th)

    def en_to_latlon(self, e_m, n_m) -> tuple[np.ndarray, np.ndarray]:
        """Local east/north metres → (lat, lon) [deg] on the origin's tangent plane."""
        return unproject(e_m, n_m, self.origin_lat_deg, self.origin_lon_deg)


@dataclass(frozen=True)
class Beacon:
    mac: int  # 48-bit MAC as an integer
    x_m: float
    y_m: float
    floor: int = 0
    z_m: float = 2.4  # above the floor's walking surface (wall mount)
    rssi_1m_dbm: float = -59.0  # measured power: mean RSSI at 1 m
    adv_interval_ms: int = 200  # advertising interval (5 Hz), plus the spec's 0-10 ms advDelay

    @property
    def mac_text(self) -> str:
        return ":".join(f"{(self.mac >> (8 * k)) & 0xFF:02x}" for k in range(5, -1, -1))


@dataclass(frozen=True)
class Door:
    name: str
    x_m: float
    y_m: float
    width_m: float
    floor: int = 0
    landmark_id: int = 0  # the NFC tag at the door's centre (0: none)


def inside(footprint_m: np.ndarray | None, x_m, y_m) -> np.ndarray:
    """Boolean array: the points lie inside the building (True everywhere without a footprint)."""
    x, y = np.asarray(x_m, float), np.asarray(y_m, float)
    if footprint_m is None:
        return np.ones(np.broadcast(x, y).shape, dtype=bool)
    out = np.zeros(np.broadcast(x, y).shape, dtype=bool)
    for x0, y0, x1, y1 in np.asarray(footprint_m, float):
        out |= (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    return out
