"""`stridefix export` on a simulated walk: each format read back with its own library holds every
logged pose, in the right place (to 1 mm through project()), on its floor and at its time."""

from __future__ import annotations

import datetime
import json
import xml.etree.ElementTree as ET

import geojson
import gpxpy
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.export.georef import from_site
from stridefix_analyzer.io.sitefile import read_site
from stridefix_analyzer.schemes import scheme_name
from stridefix_common.geodesy import project

KML = "{http://www.opengis.net/kml/2.2}"
GX = "{http://www.google.com/kml/ext/2.2}"


@pytest.fixture(scope="session")
def geo(geo_walk):
    return from_site(read_site(geo_walk["site"]), str(geo_walk["site"]))


def _export(cli, geo_walk, out, *extra):
    proc = cli("export", str(geo_walk["log"]), "--site", str(geo_walk["site"]), "--out", str(out), *extra)
    assert proc.returncode == 0, proc.stderr
    return proc


def _column(msgs, field):
    return np.array([getattr(m, field) for m in msgs])


def test_the_walk_has_a_rotated_geo_reference_and_two_floors(geo, logged_poses):
    # the checks below mean something only if the map frame is turned and the walk changes floor
    assert geo.rotation_deg == 20.0 and geo.origin_alt_m == 408.0
    assert set(_column(logged_poses["POSE"], "floor")) == {0, 1}


def test_geojson_positions_project_back_onto_the_logged_poses(cli, geo_walk, geo, logged_poses, tmp_path):
    _export(cli, geo_walk, tmp_path / "walk.geojson")
    text = (tmp_path / "walk.geojson").read_text()
    valid = geojson.loads(text)
    assert valid.is_valid, valid.errors()
    doc = json.loads(text)  # geojson.loads rounds positions to 6 decimals (10 cm): read them as written
    poses = logged_poses["POSE"]
    coords = np.array([c for f in doc["features"] for c in np.atleast_2d(f["geometry"]["coordinates"])])
    assert len(coords) == len(poses) == 3644
    # RFC 7946 order: longitude, latitude; back to east-north with project(), to the map frame by the rotation
    e, n = project(coords[:, 1], coords[:, 0], geo.origin_lat_deg, geo.origin_lon_deg)
    x, y = geo.en_to_map(e, n)
    assert_allclose(x, _column(poses, "x_m"), atol=1e-3)
    assert_allclose(y, _column(poses, "y_m"), atol=1e-3)
    # one Feature per floor leg, its floor a property and its altitude the origin's + the floor height
    floors = _column(poses, "floor")
    assert len(doc["features"]) == 1 + np.count_nonzero(np.diff(floors))
    per_point_floor = np.concatenate(
        [
            [f["properties"]["floor"]] * len(np.atleast_2d(f["geometry"]["coordinates"]))
            for f in doc["features"]
        ]
    )
    assert (per_point_floor == floors).all()
    assert_allclose(coords[:, 2], np.where(floors == 1, 411.5, 408.0))
    times = [t for f in doc["features"] for t in f["properties"]["coordTimes"]]
    first = datetime.datetime.fromisoformat(times[0].replace("Z", "+00:00"))
    assert first == datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc) + datetime.timedelta(
        microseconds=poses[0].t_us
    )


def test_gpx_has_every_pose_with_its_time(cli, geo_walk, geo, logged_poses, tmp_path):
    _export(cli, geo_walk, tmp_path / "walk.gpx", "--start-utc", "2024-05-02T09:30:00Z")
    gpx = gpxpy.parse((tmp_path / "walk.gpx").read_text())
    poses = logged_poses["POSE"]
    assert [t.name for t in gpx.tracks] == ["primary"]
    points = [p for seg in gpx.tracks[0].segments for p in seg.points]
    assert len(points) == len(poses)
    start = datetime.datetime(2024, 5, 2, 9, 30, tzinfo=datetime.timezone.utc)
    expect = [start + datetime.timedelta(microseconds=m.t_us) for m in poses]
    assert [p.time for p in points] == expect
    # a segment per floor leg, the floor's altitude as elevation
    assert len(gpx.tracks[0].segments) == 1 + np.count_nonzero(np.diff(_column(poses, "floor")))
    assert_allclose([p.elevation for p in points], geo.altitude_m(_column(poses, "floor")))
    lat, lon = geo.to_latlon(_column(poses, "x_m"), _column(poses, "y_m"))
    assert_allclose([p.latitude for p in points], lat, atol=1e-9)
    assert_allclose([p.longitude for p in points], lon, atol=1e-9)


def test_kml_has_a_coordinate_and_a_time_per_pose_for_every_scheme(cli, geo_walk, logged_poses, tmp_path):
    _export(cli, geo_walk, tmp_path / "walk.kml", "--scheme", "all")
    root = ET.parse(tmp_path / "walk.kml").getroot()
    folders = root.iter(f"{KML}Folder")
    per_scheme = {
        f.find(f"{KML}name").text: (len(list(f.iter(f"{GX}coord"))), len(list(f.iter(f"{KML}when"))))
        for f in folders
    }
    expect = {ch[len("POSE_") :].lower(): len(m) for ch, m in logged_poses.items() if ch != "POSE"}
    assert len(expect) == 8
    assert per_scheme == {name: (n, n) for name, n in expect.items()}


def test_one_scheme_by_name(cli, geo_walk, logged_poses, tmp_path):
    proc = _export(cli, geo_walk, tmp_path / "ekf.geojson", "--scheme", "ekf")
    doc = json.loads((tmp_path / "ekf.geojson").read_text())
    assert {f["properties"]["track"] for f in doc["features"]} == {"ekf"}
    assert {f["properties"]["channel"] for f in doc["features"]} == {"POSE_EKF"}
    n = sum(len(f["properties"]["coordTimes"]) for f in doc["features"])
    assert n == len(logged_poses["POSE_EKF"])
    assert f"1 track(s) (ekf), {n} poses" in proc.stdout
    assert scheme_name(logged_poses["POSE_EKF"][0].scheme) == "ekf"
