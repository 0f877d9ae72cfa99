"""Site file version 2: every rule of io/site_v2.py rejects its variant with its own words (the C
reader is held to the same words by test_site.c), version-1 and -2 files are refused with the rebuild hint,
and a site without version-2 content round-trips empty."""

from __future__ import annotations

import importlib.util
import math
import pathlib

import pytest
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.io.sitefile import SiteFileError


def _vectors():
    path = pathlib.Path(__file__).resolve().parents[2] / "vectors" / "gen_site_vectors.py"
    spec = importlib.util.spec_from_file_location("gen_site_vectors", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_V = _vectors()

#: each version-2 variant and the reason the reader must give (the vector site: floors -1..1)
EXPECTED = {
    "altitude_nan": "origin_alt_m is nan, must be finite",
    "geo_rotation_inf": "geo_rotation_deg is -inf, must be finite",
    "wall_inf": "wall 1: end points (10, 0) - (10, inf) not finite",
    "wall_floor": "wall 1: floor 2 outside -1..1",
    "wall_zero_length": "wall 2: zero length at (-2.5, 1.5)",
    "port_kind": "port 1: kind 4 unknown (1 door, 2 stairs, 3 elevator)",
    "port_position_nan": "port 0: position (nan, 0) not finite",
    "port_radius_zero": "port 1: port_radius_m = 0, must be finite and > 0",
    "port_floors_order": "port 1: floor_lo 1 above floor_hi 0",
    "port_floors_range": "port 1: floors -2..1 outside -1..1",
    "beacon_id_range": "beacon 2: id 281474976710656 outside 0..2^48-1",
    "beacon_id_negative": "beacon 0: id -1 outside 0..2^48-1",
    "beacon_order": "beacon 2: id 0xbeac20230001 not above beacon 1's 0xbeac20230001 (ids must be strictly ascending)",
    "beacon_position_inf": "beacon 1: position (2.5, inf) not finite",
    "beacon_floor": "beacon 0: floor -2 outside -1..1",
    "beacon_rssi_inf": "beacon 1: beacon_rssi_1m_dbm is inf, must be finite or NaN (unknown)",
    "ble_rssi_nan": "ble_rssi_1m_dbm is nan, must be finite",
    "ble_exponent_zero": "ble_path_loss_exponent = 0, must be finite and > 0",
    "ble_sigma_negative": "ble_range_sigma_db = -1, must be finite and > 0",
}


@pytest.mark.parametrize("name,data", [(n, d) for n, d, _, _ in _V.v2_variants()], ids=lambda v: str(v)[:20])
def test_each_v2_rule_rejected_with_its_message(name, data):
    with pytest.raises(SiteFileError) as info:
        sitefile.decode_site_file(data, "v.sfsite")
    assert info.value.kind == "field"
    assert str(info.value) == f"v.sfsite: {EXPECTED[name]}"


def test_every_v2_rule_has_a_variant():
    assert sorted(EXPECTED) == sorted(n for n, *_ in _V.v2_variants())


@pytest.mark.parametrize("version", [1, 2])
def test_old_versions_refused_with_rebuild_hint(version):
    payload = sitefile.encode_site_file(_V.vector_site())[sitefile.HEADER_SIZE :]
    with pytest.raises(SiteFileError) as info:
        sitefile.decode_site_file(_V.frame(payload, version=version), "old.sfsite")
    assert info.value.kind == "version"
    assert str(info.value) == (
        f"old.sfsite: format version {version}, this build reads 3: rebuild it with `stridefix radiomap build`"
    )


def test_without_v2_content_round_trips_empty(tmp_path):
    path = tmp_path / "plain.sfsite"
    sitefile.write_site(path, sitefile.new_site(name="plain"))
    got = sitefile.read_site(path)
    assert (got.n_walls, got.n_ports, got.n_beacons) == (0, 0, 0)
    assert not got.has_geo


def test_geo_rules_only_with_has_geo():
    site = sitefile.new_site(origin_alt_m=math.nan)
    sitefile.validate_site(site)  # has_geo false: the altitude is not used
    site.has_geo = True
    with pytest.raises(sitefile.SiteValidationError, match="origin_alt_m is nan"):
        sitefile.validate_site(site)


def test_model_only_checked_with_beacons():
    site = sitefile.new_site(ble_path_loss_exponent=0.0)
    sitefile.validate_site(site)
    site = sitefile.new_site(
        beacon_id=[5],
        beacon_x_m=[0.0],
        beacon_y_m=[0.0],
        beacon_floor=[0],
        beacon_rssi_1m_dbm=[math.nan],
        ble_rssi_1m_dbm=-59.0,
        ble_path_loss_exponent=0.0,
        ble_range_sigma_db=6.0,
    )
    with pytest.raises(sitefile.SiteValidationError, match="ble_path_loss_exponent = 0"):
        sitefile.validate_site(site)
