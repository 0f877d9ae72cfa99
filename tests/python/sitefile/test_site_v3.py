"""Site file version 3 (the context map): every rule of io/site_v3.py rejects its variant with its own
words (the C reader is held to the same words by test_site.c), the vector site's context map
round-trips, a site without one round-trips empty, and stairs without a step count are fine until the
site has contexts."""

from __future__ import annotations

import importlib.util
import pathlib

import pytest
from stridefix import site_t
from stridefix_analyzer.io import site_v3, sitefile
from stridefix_analyzer.io.sitefile import SiteFileError


def _vectors():
    path = pathlib.Path(__file__).resolve().parents[2] / "vectors" / "gen_site_vectors.py"
    spec = importlib.util.spec_from_file_location("gen_site_vectors", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_V = _vectors()

#: each version-3 variant and the reason the reader must give (the vector site: floors -1..1,
#: buildings A and B, ports door and stairs, contexts outdoor, A/0 and B/1)
EXPECTED = {
    "outline_building_range": "outline vertex 6: building 2 outside 0..1",
    "outline_inf": "outline vertex 3: position (0, inf) not finite",
    "outline_not_consecutive": "outline vertex 3: building 0's vertices not consecutive (its first is vertex 0)",
    "outline_too_few": "building 1: 2 outline vertices, needs at least 3",
    "port_building_range": "port 1: port_building 2 outside -1..1",
    "port_outdoor": "port 0: port_outdoor 2 is not 0 or 1",
    "port_steps_negative": "port 0: port_steps -1 is negative",
    "port_stairs_no_steps": "port 1: stairs with port_steps 0 (a staircase needs its step count when the "
    "site has contexts)",
    "port_end_nan": "port 1: endpoints (2, 3.5) - (4, nan) not finite",
    "link_range": "link 0: port 2 outside 0..1",
    "link_self": "link 0: links port 0 with itself",
    "context_kind": "context 1: kind 4 unknown (1 outdoor, 2 building, 3 floor)",
    "context_outdoor_building": "context 0: an outdoor context has building 0, must be -1",
    "context_building_range": "context 2: building 2 outside 0..1",
    "context_floor": "context 1: floor 2 outside -1..1",
    "context_scheme": "context 1: scheme 8 is not a fusion scheme (0..7)",
    "context_method": "context 1: method 3 is not wifi (1), gnss (2) or ble (4)",
    "context_cdd_method": "context 2: cdd_method 5 is not wifi (1), gnss (2) or ble (4)",
    "context_min_hits": "context 1: cdd_min_hits 0, must be >= 1",
    "context_two_outdoor": "context 1: a second outdoor context (context 0 is one)",
    "context_duplicate": "context 2: kind 3, building 1, floor 1 already context 1",
    "cdd_context_range": "cdd 2: context 3 outside 0..2",
    "cdd_order": "cdd 2: context 1 below cdd 1's 2 (must be non-decreasing)",
    "cdd_id_range": "cdd 1: id 281474976710656 outside 0..2^48-1",
    "cdd_dbm_inf": "cdd 1: cdd_min_dbm is -inf, must be finite",
    "cdd_gnss": "cdd 0: context 0 is recognised by GNSS and has no constellation",
}


@pytest.mark.parametrize("name,data", [(n, d) for n, d, _, _ in _V.v3_variants()], ids=lambda v: str(v)[:24])
def test_each_v3_rule_rejected_with_its_message(name, data):
    with pytest.raises(SiteFileError) as info:
        sitefile.decode_site_file(data, "v.sfsite")
    assert info.value.kind == "field"
    assert str(info.value) == f"v.sfsite: {EXPECTED[name]}"


def test_every_v3_rule_has_a_variant():
    assert sorted(EXPECTED) == sorted(n for n, *_ in _V.v3_variants())


def test_v3_table_covers_every_v3_field_of_site_t():
    """V3_ARRAYS names every array after ble_range_sigma_db in site_t.lcm (the one list)."""
    lcm = (pathlib.Path(__file__).resolve().parents[3] / "lcmtypes" / "stridefix" / "site_t.lcm").read_text()
    tail = lcm.split("format version 3", 1)[1]
    fields = [line.split("//")[0].split() for line in tail.splitlines()]
    arrays = {f[1].split("[")[0] for f in fields if len(f) == 2 and "[" in f[1]}
    assert arrays == {a for names in site_v3.V3_ARRAYS.values() for a in names}


def test_vector_context_map_round_trips(tmp_path):
    path = tmp_path / "v.sfsite"
    want = _V.vector_site()
    sitefile.write_site(path, want)
    got = sitefile.read_site(path)
    for arrays in site_v3.V3_ARRAYS.values():
        for name in arrays:  # float32 fields: the vector's values are exact in float32
            assert list(getattr(got, name)) == list(getattr(want, name)), name
    assert (got.n_buildings, got.n_outline, got.n_links, got.n_contexts, got.n_cdd) == (2, 7, 1, 3, 3)


def test_without_context_map_round_trips_empty(tmp_path):
    path = tmp_path / "plain.sfsite"
    site = sitefile.new_site(
        name="plain",
        floor_height_m=[0.0, 3.5],
        port_kind=[site_t.PORT_STAIRS],
        port_x_m=[1.0],
        port_y_m=[2.0],
        port_radius_m=[1.5],
        port_floor_lo=[0],
        port_floor_hi=[1],
    )
    sitefile.write_site(path, site)  # stairs with the neutral 0 steps: no contexts, no rule
    got = sitefile.read_site(path)
    assert (got.n_buildings, got.n_contexts, got.n_cdd, got.n_links) == (0, 0, 0, 0)
    assert list(got.port_steps) == [0] and list(got.port_building) == [-1]
    assert (got.port_lo_x_m[0], got.port_hi_y_m[0]) == (1.0, 2.0)  # endpoints at the centre
