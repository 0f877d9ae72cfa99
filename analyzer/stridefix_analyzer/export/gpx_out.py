"""GPX 1.1 of pose tracks (gpxpy): one ``<trk>`` per track, one ``<trkseg>`` per floor.

Every pose is a ``<trkpt>`` with its latitude/longitude [deg], ``<ele>`` = the floor's altitude (the
origin's + its walking-surface height [m]) and ``<time>`` (UTC: ``--start-utc`` + board time). A
floor change starts a new segment, so a GPS tool draws each floor's part apart; the track's
``<type>`` is the channel it came from.
"""

from __future__ import annotations

import datetime
import os
from collections.abc import Sequence

from stridefix_analyzer.export.extra import need
from stridefix_analyzer.export.georef import GeoRef
from stridefix_analyzer.export.tracks import EPOCH, Track, utc_times


def gpx_text(tracks: Sequence[Track], geo: GeoRef, start: datetime.datetime = EPOCH) -> str:
    """The GPX document of ``tracks`` (module docstring)."""
    gpxpy = need("gpxpy.gpx", "--format gpx")
    doc = gpxpy.GPX()
    doc.creator = "StrideFix stridefix export"
    for track in tracks:
        p = track.poses
        lat, lon = geo.to_latlon(p["x_m"], p["y_m"])
        alt = geo.altitude_m(p["floor"])
        times = utc_times(p["t_us"], start)
        trk = gpxpy.GPXTrack(
            name=track.name, description=f"StrideFix {track.channel} poses, a segment per floor"
        )
        trk.type = track.channel
        for leg in track.legs():
            seg = gpxpy.GPXTrackSegment()
            for i in range(leg.start, leg.stop):
                seg.points.append(
                    gpxpy.GPXTrackPoint(float(lat[i]), float(lon[i]), elevation=float(alt[i]), time=times[i])
                )
            trk.segments.append(seg)
        doc.tracks.append(trk)
    return str(doc.to_xml(version="1.1"))


def write_gpx(
    path: str | os.PathLike[str], tracks: Sequence[Track], geo: GeoRef, start: datetime.datetime = EPOCH
) -> int:
    """Write the tracks' GPX to ``path``; returns the number of track points."""
    text = gpx_text(tracks, geo, start)  # before the file is opened: a failure leaves no empty file
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    return sum(len(t) for t in tracks)
