"""The site's geo-reference: map frame [m] ↔ WGS-84 latitude/longitude [deg] and floor → altitude.

A site file with ``has_geo`` places its map frame on the Earth (site_t, firmware ``sf_geo``): the
map origin is at (``origin_lat_deg``, ``origin_lon_deg``, ``origin_alt_m``) and the map frame is the
local east-north frame at the origin turned counter-clockwise by ``geo_rotation_deg`` θ, so

    x =  cos θ·e + sin θ·n        e = cos θ·x − sin θ·y
    y = −sin θ·e + cos θ·n        n = sin θ·x + cos θ·y

(the right-hand pair is the exact inverse: a rotation's inverse is its transpose). East-north ↔
latitude/longitude is the one local tangent plane of :mod:`stridefix_common.geodesy`
(``project``/``unproject``), the plane the firmware, the importers and the site builder use, so an
exported track lands where the estimator's fixes came from. Outside the site's table a floor's height
continues as :mod:`stridefix_analyzer.scoring.floor_height` says; a floor's altitude is the origin's
plus its walking-surface height.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping
from typing import Any

import numpy as np
import numpy.typing as npt
from stridefix_common.geodesy import project, unproject

from stridefix_analyzer.io.sitefile import SiteFileError, read_site
from stridefix_analyzer.scoring.floor_height import FloorHeights, from_table

Array = npt.NDArray[np.float64]

#: how to give a site a geo-reference, for the error of a site without one
HOW_TO_GEOREFERENCE = (
    "give it one with `stridefix radiomap build ... --origin-deg LAT,LON` or a [geo] table "
    "(origin_lat_deg, origin_lon_deg, origin_alt_m, rotation_deg) in the --building file "
    "(docs/building.md)"
)


class GeoRefError(ValueError):
    """The site cannot place the walk on the Earth (unreadable, or no geo-reference); names the file."""


@dataclasses.dataclass(frozen=True)
class GeoRef:
    """A site's geo-reference and floor heights.

    Attributes
    ----------
    origin_lat_deg, origin_lon_deg : float
        WGS-84 position of the map origin [deg].
    origin_alt_m : float
        Its height above the WGS-84 ellipsoid [m].
    rotation_deg : float
        Map frame = local east-north turned counter-clockwise by this [deg].
    floors : FloorHeights
        Floor index → walking-surface height above the origin [m].
    """

    origin_lat_deg: float
    origin_lon_deg: float
    origin_alt_m: float
    rotation_deg: float
    floors: FloorHeights

    def _cos_sin(self) -> tuple[float, float]:
        a = math.radians(self.rotation_deg)
        return math.cos(a), math.sin(a)

    def map_to_en(self, x_m: npt.ArrayLike, y_m: npt.ArrayLike) -> tuple[Array, Array]:
        """Map frame → local (east, north) about the origin [m]."""
        c, s = self._cos_sin()
        x, y = np.asarray(x_m, dtype=np.float64), np.asarray(y_m, dtype=np.float64)
        return c * x - s * y, s * x + c * y

    def en_to_map(self, east_m: npt.ArrayLike, north_m: npt.ArrayLike) -> tuple[Array, Array]:
        """Local (east, north) about the origin → map frame [m] (the inverse of :meth:`map_to_en`)."""
        c, s = self._cos_sin()
        e, n = np.asarray(east_m, dtype=np.float64), np.asarray(north_m, dtype=np.float64)
        return c * e + s * n, -s * e + c * n

    def to_latlon(self, x_m: npt.ArrayLike, y_m: npt.ArrayLike) -> tuple[Array, Array]:
        """Map frame [m] → (latitude, longitude) [deg]; longitude wrapped into [−180, 180)."""
        e, n = self.map_to_en(x_m, y_m)
        lat, lon = unproject(e, n, self.origin_lat_deg, self.origin_lon_deg)
        return lat, (lon + 180.0) % 360.0 - 180.0

    def to_map(self, lat_deg: npt.ArrayLike, lon_deg: npt.ArrayLike) -> tuple[Array, Array]:
        """(latitude, longitude) [deg] → map frame [m] (what the firmware's ``sf_geo_to_map`` does)."""
        lon = np.asarray(lon_deg, dtype=np.float64)
        # across the antimeridian the short way round, as sf_geo
        lon = self.origin_lon_deg + (lon - self.origin_lon_deg + 180.0) % 360.0 - 180.0
        e, n = project(np.asarray(lat_deg, dtype=np.float64), lon, self.origin_lat_deg, self.origin_lon_deg)
        return self.en_to_map(e, n)

    def height_m(self, floor: npt.ArrayLike) -> Array:
        """Walking-surface height of each floor above the origin [m]. A floor the site's table does
        not cover and whose spacing is unknown (a one-floor site, no CONFIG) gets the nearest floor's."""
        f = np.asarray(floor, dtype=np.int64)
        z = np.asarray(self.floors.z_m(f), dtype=np.float64)
        if self.floors.table_m and not np.all(np.isfinite(z)):
            table = np.asarray(self.floors.table_m, dtype=np.float64)
            nearest = table[np.clip(f - self.floors.lowest_floor, 0, table.size - 1)]
            z = np.where(np.isfinite(z), z, nearest)
        return np.where(np.isfinite(z), z, 0.0)

    def altitude_m(self, floor: npt.ArrayLike) -> Array:
        """Height of each floor's walking surface above the WGS-84 ellipsoid [m]."""
        return self.origin_alt_m + self.height_m(floor)


def from_site(site: Any, path: str = "<site>", config: Mapping[str, str] | None = None) -> GeoRef:
    """The :class:`GeoRef` of a ``site_t``.

    Raises
    ------
    GeoRefError
        The site has no geo-reference (the message says how to give it one).
    """
    if not site.has_geo:
        raise GeoRefError(f"{path}: the site needs a geo-reference (has_geo is false); {HOW_TO_GEOREFERENCE}")
    floors = from_table(site.floor_height_m, site.lowest_floor, f"site {path}", config)
    return GeoRef(
        origin_lat_deg=float(site.origin_lat_deg),
        origin_lon_deg=float(site.origin_lon_deg),
        origin_alt_m=float(site.origin_alt_m),
        rotation_deg=float(site.geo_rotation_deg),
        floors=floors,
    )


def read_site_file(path: str | os.PathLike[str]) -> Any:
    """The ``site_t`` of a site file, its errors as :class:`GeoRefError` (naming the file)."""
    try:
        return read_site(path)
    except SiteFileError as exc:
        raise GeoRefError(str(exc)) from exc
