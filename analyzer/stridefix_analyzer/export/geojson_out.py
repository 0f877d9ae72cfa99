"""GeoJSON (RFC 7946) of pose tracks: one Feature per track and floor, for QGIS or geojson.io.

Each leg of a track on one floor (:meth:`~.tracks.Track.legs`) is a ``LineString`` (a ``Point`` for a
leg of one pose) with positions ``[longitude, latitude, altitude]`` (RFC 7946's order; altitude =
the origin's + the floor's walking-surface height [m]) in WGS-84 degrees with 9 decimals (0.1 mm: the
track goes back to the map frame to the millimetre). Properties: ``track`` (``primary`` or the
scheme), ``channel``, ``floor``, ``altitude_m``, ``start``/``end`` (ISO 8601 UTC), ``coordTimes``
(one ISO time per position, the name toGeoJSON and geojson.io read), ``t_s`` (board time [s]),
``sigma_m`` (the pose's 1-σ [m]) and ``stroke`` (the scheme's report colour, simplestyle-spec).
"""

from __future__ import annotations

import datetime
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from stridefix_analyzer.export.extra import need
from stridefix_analyzer.export.georef import GeoRef
from stridefix_analyzer.export.tracks import EPOCH, Track, utc_times
from stridefix_analyzer.schemes import scheme_code, scheme_colour

#: decimals of a coordinate: 1e-9° is ≤ 0.11 mm on the Earth
PRECISION = 9
PRIMARY_COLOUR = "#000000"


def _colour(track: Track) -> str:
    try:
        return scheme_colour(scheme_code(track.name))
    except ValueError:
        return PRIMARY_COLOUR


def features(tracks: Sequence[Track], geo: GeoRef, start: datetime.datetime = EPOCH) -> Any:
    """The ``geojson.FeatureCollection`` of ``tracks`` (module docstring)."""
    geojson = need("geojson", "--format geojson")
    out = []
    for track in tracks:
        p = track.poses
        lat, lon = geo.to_latlon(p["x_m"], p["y_m"])
        alt = geo.altitude_m(p["floor"])
        times = [t.isoformat().replace("+00:00", "Z") for t in utc_times(p["t_us"], start)]
        for leg in track.legs():
            coords = [[float(a), float(b), float(c)] for a, b, c in zip(lon[leg], lat[leg], alt[leg])]
            if len(coords) > 1:
                geometry = geojson.LineString(coords, precision=PRECISION)
            else:
                geometry = geojson.Point(coords[0], precision=PRECISION)
            props = {
                "track": track.name,
                "channel": track.channel,
                "floor": int(p["floor"][leg.start]),
                "altitude_m": float(alt[leg.start]),
                "start": times[leg][0],
                "end": times[leg][-1],
                "coordTimes": times[leg],
                "t_s": np.round(np.asarray(p["t_us"][leg]) * 1e-6, 6).tolist(),
                "sigma_m": [round(float(s), 4) for s in p["sigma_m"][leg]],
                "stroke": _colour(track),
            }
            out.append(geojson.Feature(geometry=geometry, properties=props))
    return geojson.FeatureCollection(out)


def write_geojson(
    path: str | os.PathLike[str], tracks: Sequence[Track], geo: GeoRef, start: datetime.datetime = EPOCH
) -> int:
    """Write the tracks' GeoJSON to ``path``; returns the number of features."""
    geojson = need("geojson", "--format geojson")
    doc = features(tracks, geo, start)
    with open(path, "w", encoding="utf-8") as f:
        geojson.dump(doc, f)
        f.write("\n")
    return len(doc["features"])
