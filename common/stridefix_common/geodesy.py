"""WGS-84 and the local tangent plane every StrideFix side uses for latitude/longitude ↔ metres.

A local tangent plane with the WGS-84 radii of curvature at the origin's latitude φ0:
``x = N(φ0)·cos φ0·(λ − λ0)``, ``y = M(φ0)·(φ − φ0)`` (angles in radians), with the prime-vertical
radius ``N = a / sqrt(1 − e²·sin²φ0)`` and the meridian radius ``M = a·(1 − e²) / (1 − e²·sin²φ0)^1.5``.
Over a building (< 1 km) it differs from a full ENU conversion by millimetres. The firmware's sf_geo
uses the same plane; the importers (GNSS, truth), the site builder (geo-referenced beacons), the
organisers' scorer and the simulator's GNSS all go through :func:`project` / :func:`unproject`.
"""

from __future__ import annotations

import math

import numpy as np

#: WGS-84 semi-major axis [m] and first eccentricity squared.
WGS84_A = 6378137.0
WGS84_E2 = 6.69437999014e-3


def radii_m(origin_lat_deg: float) -> tuple[float, float]:
    """(prime-vertical radius N, meridian radius M) [m] at latitude ``origin_lat_deg``."""
    phi0 = math.radians(origin_lat_deg)
    w = 1.0 - WGS84_E2 * math.sin(phi0) ** 2
    return WGS84_A / math.sqrt(w), WGS84_A * (1.0 - WGS84_E2) / w**1.5


def project(
    lat_deg: np.ndarray | list[float],
    lon_deg: np.ndarray | list[float],
    origin_lat_deg: float,
    origin_lon_deg: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Latitude/longitude [deg] → local metres (x east, y north) about the origin."""
    n, m = radii_m(origin_lat_deg)
    lat = np.asarray(lat_deg, dtype=np.float64)
    lon = np.asarray(lon_deg, dtype=np.float64)
    x = n * math.cos(math.radians(origin_lat_deg)) * np.radians(lon - origin_lon_deg)
    y = m * np.radians(lat - origin_lat_deg)
    return x, y


def unproject(
    east_m: np.ndarray | list[float],
    north_m: np.ndarray | list[float],
    origin_lat_deg: float,
    origin_lon_deg: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Local metres (east, north) about the origin → latitude/longitude [deg]; inverts :func:`project`."""
    n, m = radii_m(origin_lat_deg)
    lat = origin_lat_deg + np.degrees(np.asarray(north_m, dtype=np.float64) / m)
    lon = origin_lon_deg + np.degrees(
        np.asarray(east_m, dtype=np.float64) / (n * math.cos(math.radians(origin_lat_deg)))
    )
    return lat, lon
