"""KML of pose tracks (simplekml), for Google Earth: a folder per track, a ``gx:Track`` per floor.

A ``gx:Track`` holds each pose's ``<when>`` (UTC) and ``<gx:coord>`` (longitude, latitude, altitude
= the floor's walking surface above the ellipsoid [m], altitude mode absolute), so Google Earth's
time slider replays the walk; the line takes the scheme's report colour.
"""

from __future__ import annotations

import datetime
import os
from collections.abc import Sequence

from stridefix_analyzer.export.extra import need
from stridefix_analyzer.export.georef import GeoRef
from stridefix_analyzer.export.tracks import EPOCH, Track, utc_times
from stridefix_analyzer.schemes import scheme_code, scheme_colour

PRIMARY_COLOUR = "#000000"


def _kml_colour(track: Track) -> str:
    """The track's colour as KML's aabbggrr."""
    try:
        rgb = scheme_colour(scheme_code(track.name))
    except ValueError:
        rgb = PRIMARY_COLOUR
    r, g, b = rgb[1:3], rgb[3:5], rgb[5:7]
    return f"ff{b}{g}{r}".lower()


def kml_text(tracks: Sequence[Track], geo: GeoRef, start: datetime.datetime = EPOCH) -> str:
    """The KML document of ``tracks`` (module docstring)."""
    simplekml = need("simplekml", "--format kml")
    kml = simplekml.Kml(name="StrideFix walk")
    for track in tracks:
        p = track.poses
        lat, lon = geo.to_latlon(p["x_m"], p["y_m"])
        alt = geo.altitude_m(p["floor"])
        times = [t.isoformat().replace("+00:00", "Z") for t in utc_times(p["t_us"], start)]
        folder = kml.newfolder(name=track.name, description=f"StrideFix {track.channel} poses")
        for leg in track.legs():
            gx = folder.newgxtrack(name=f"{track.name} floor {int(p['floor'][leg.start])}")
            gx.altitudemode = simplekml.AltitudeMode.absolute
            gx.newwhen(times[leg])
            gx.newgxcoord([(float(a), float(b), float(c)) for a, b, c in zip(lon[leg], lat[leg], alt[leg])])
            gx.style.linestyle.color = _kml_colour(track)
            gx.style.linestyle.width = 3
    return str(kml.kml())


def write_kml(
    path: str | os.PathLike[str], tracks: Sequence[Track], geo: GeoRef, start: datetime.datetime = EPOCH
) -> int:
    """Write the tracks' KML to ``path``; returns the number of poses written."""
    text = kml_text(tracks, geo, start)  # before the file is opened: a failure leaves no empty file
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return sum(len(t) for t in tracks)
