"""The site's geo-reference: map frame ↔ latitude/longitude, exact against the projection every side
uses (stridefix_common.geodesy.project) and the site builder's WGS-84 → map frame."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.export.georef import GeoRef, GeoRefError, from_site
from stridefix_analyzer.io.sitefile import new_site
from stridefix_analyzer.radiomap.building import to_map_frame
from stridefix_analyzer.scoring.floor_height import from_table
from stridefix_common.geodesy import project


def _geo(rotation_deg: float, lat: float = 47.3769, lon: float = 8.5417) -> GeoRef:
    return GeoRef(lat, lon, 408.0, rotation_deg, from_table([0.0, 3.5, 7.5], -1, "test"))


@pytest.mark.parametrize("rotation_deg", [0.0, 20.0, -135.0, 90.0])
def test_map_to_latlon_round_trips_through_project(rotation_deg):
    # GIVEN map points over a building and beyond (±2 km)
    rng = np.random.default_rng(7)
    x, y = rng.uniform(-2000, 2000, 500), rng.uniform(-2000, 2000, 500)
    geo = _geo(rotation_deg)
    # WHEN they go to latitude/longitude and back with project() and the map rotation
    lat, lon = geo.to_latlon(x, y)
    e, n = project(lat, lon, geo.origin_lat_deg, geo.origin_lon_deg)
    bx, by = geo.en_to_map(e, n)
    # THEN they come back to 1 µm (the rotation's inverse is exact), and so does geo.to_map
    assert_allclose(bx, x, atol=1e-6)
    assert_allclose(by, y, atol=1e-6)
    assert_allclose(np.stack(geo.to_map(lat, lon)), np.stack([x, y]), atol=1e-6)


@pytest.mark.parametrize("rotation_deg", [0.0, 20.0, 250.0])
def test_the_site_builders_forward_map_agrees(rotation_deg):
    # the building file's geo-located beacons go into the map frame with radiomap.building.to_map_frame
    geo = _geo(rotation_deg)
    ref = {
        "origin_lat_deg": geo.origin_lat_deg,
        "origin_lon_deg": geo.origin_lon_deg,
        "rotation_deg": rotation_deg,
    }
    for x, y in [(12.5, -3.0), (-40.0, 75.25), (0.0, 0.0)]:
        lat, lon = geo.to_latlon(x, y)
        assert_allclose(to_map_frame(ref, float(lat), float(lon)), (x, y), atol=1e-6)


def test_rotation_direction():
    # the map frame is east-north turned counter-clockwise by θ: at θ = 90° the map's +x points north
    geo = _geo(90.0)
    e, n = geo.map_to_en(10.0, 0.0)
    assert_allclose([e, n], [0.0, 10.0], atol=1e-12)
    lat, lon = geo.to_latlon(10.0, 0.0)
    assert lat > geo.origin_lat_deg and abs(lon - geo.origin_lon_deg) < 1e-12
    # 10 m north is 10 / M(φ0) rad of latitude, M ≈ 6.367e6 m at 47.4°: 9.0e-5 deg
    assert_allclose(lat - geo.origin_lat_deg, 10.0 / 6.367e6 * 180.0 / np.pi, rtol=1e-3)


def test_longitude_wraps_at_the_antimeridian():
    geo = _geo(0.0, lat=-16.5, lon=179.9999)
    lat, lon = geo.to_latlon(500.0, 0.0)  # 500 m east crosses 180°
    assert -180.0 <= lon < -179.99
    assert_allclose(np.stack(geo.to_map(lat, lon)), [500.0, 0.0], atol=1e-6)


def test_floor_altitude_is_origin_plus_floor_height():
    geo = _geo(0.0)  # floors -1, 0, 1 at 0, 3.5, 7.5 m
    assert_allclose(geo.altitude_m([-1, 0, 1]), [408.0, 411.5, 415.5])
    # outside the table: continued at the table's mean spacing (3.75 m)
    assert_allclose(geo.altitude_m([2, -2]), [419.25, 404.25])


def test_a_site_without_geo_reference_is_refused_with_the_way_to_give_one():
    site = new_site(floor_height_m=[0.0], n_floors=1)
    with pytest.raises(GeoRefError) as err:
        from_site(site, "x.sfsite")
    text = str(err.value)
    assert text.startswith("x.sfsite: the site needs a geo-reference")
    assert "--origin-deg" in text and "[geo]" in text
