"""sitefile: write → read round trip, and every kind of corrupt or invalid file rejected with a
message naming the file and the problem."""

from __future__ import annotations

import importlib.util
import pathlib
import struct
import zlib

import numpy as np
import pytest
from stridefix import site_t
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.io.sitefile import HEADER_SIZE, SiteFileError

#: the ``float`` fields of site_t.lcm (the others are double, integers, booleans or strings)
_FLOAT32_FIELDS = {
    "cell_size_m",
    "rp_x_m",
    "rp_y_m",
    "entry_mean_dbm",
    "entry_std_db",
    "fix_floor_cov_m2",
    "fix_cov_per_acc2",
    "fix_bias_sigma_m",
    "fix_bias_length_m",
    "fix_white_share",
    "wall_x0_m",
    "wall_y0_m",
    "wall_x1_m",
    "wall_y1_m",
    "port_x_m",
    "port_y_m",
    "port_radius_m",
    "beacon_x_m",
    "beacon_y_m",
    "beacon_rssi_1m_dbm",
    "ble_rssi_1m_dbm",
    "ble_path_loss_exponent",
    "ble_range_sigma_db",
}


def _f32(values):
    return np.asarray(values, dtype=np.float32).astype(np.float64)


def test_round_trip_every_value_equal(tmp_path, vector_site):
    path = tmp_path / "site.sfsite"
    size = sitefile.write_site(path, vector_site)
    assert size == path.stat().st_size
    got = sitefile.read_site(path)
    # every field of site_t (a new one cannot be missed); float32 fields come back as the float32
    # nearest to what was written, exactly, the rest exactly as written
    for name in site_t.__slots__:
        want, back = getattr(vector_site, name), getattr(got, name)
        if name in _FLOAT32_FIELDS:
            assert np.array_equal(np.asarray(back, float), _f32(want), equal_nan=True), name
        elif isinstance(want, list | tuple):
            assert list(back) == list(want), name
        else:
            assert back == want, name


def test_header_layout(tmp_path, vector_site):
    path = tmp_path / "site.sfsite"
    sitefile.write_site(path, vector_site)
    data = path.read_bytes()
    magic, version, length, crc, reserved = struct.unpack_from("<8sIIII", data)
    assert (magic, version, reserved) == (b"SFSITE\0\x01", 3, 0)
    assert length == len(data) - 24
    assert crc == zlib.crc32(data[24:])
    assert data[24:] == vector_site.encode()


def test_write_refuses_invalid_site(tmp_path, vector_site):
    vector_site.entry_rp = [0, 1, 300, 1, 4, 2, 4]
    path = tmp_path / "bad.sfsite"
    with pytest.raises(SiteFileError) as info:
        sitefile.write_site(path, vector_site)
    assert info.value.kind == "field"
    assert str(info.value) == f"{path}: not written: entry 2: rp index 300 outside 0..5"
    assert not path.exists()


def _variant_params():
    """The corrupt/invalid files of tests/vectors/gen_site_vectors.py (also run by test_site.c)."""
    path = pathlib.Path(__file__).resolve().parents[2] / "vectors" / "gen_site_vectors.py"
    spec = importlib.util.spec_from_file_location("gen_site_vectors", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return [pytest.param(name, data, kind, c_text, id=name) for name, data, kind, c_text in module.variants()]


@pytest.mark.parametrize("name,data,kind,c_text", _variant_params())
def test_variant_rejected(tmp_path, name, data, kind, c_text):
    path = tmp_path / f"{name}.sfsite"
    path.write_bytes(data)
    with pytest.raises(SiteFileError) as info:
        sitefile.read_site(path)
    assert info.value.kind == kind
    assert str(info.value).startswith(f"{path}: ")


@pytest.mark.parametrize(
    "field,offset,value,kind,text",
    [
        ("magic", 0, b"XFSITE\0\x01", "magic", "bad magic 58 46 53 49 54 45 00 01"),
        ("version", 8, struct.pack("<I", 7), "version", "format version 7, this reader supports 3"),
        ("length", 12, struct.pack("<I", 5), "length", "length mismatch (trailing bytes): header says 5"),
        ("crc", 16, struct.pack("<I", 0x12345678), "crc", "CRC-32 mismatch: header says 0x12345678"),
        ("reserved", 20, struct.pack("<I", 1), "reserved", "reserved header field is 0x00000001"),
    ],
)
def test_each_header_field_corrupted(tmp_path, vector_site, field, offset, value, kind, text):
    data = bytearray(sitefile.encode_site_file(vector_site))
    data[offset : offset + len(value)] = value
    path = tmp_path / "site.sfsite"
    path.write_bytes(bytes(data))
    with pytest.raises(SiteFileError, match=text.replace("(", r"\(").replace(")", r"\)")) as info:
        sitefile.read_site(path)
    assert info.value.kind == kind and info.value.path == str(path)


def test_truncation_at_every_length(vector_site):
    data = sitefile.encode_site_file(vector_site)
    for n in range(len(data)):
        with pytest.raises(SiteFileError) as info:
            sitefile.decode_site_file(data[:n], "cut.sfsite")
        if n < HEADER_SIZE:
            assert info.value.kind == "short"
            assert str(info.value) == (
                f"cut.sfsite: file has only {n} bytes; a site file starts with a 24-byte header"
            )
        else:
            assert info.value.kind == "length"
            assert str(info.value) == (
                f"cut.sfsite: length mismatch (truncated): header says "
                f"{len(data) - HEADER_SIZE} payload bytes, file has "
                f"{n - HEADER_SIZE}"
            )


def test_every_payload_byte_flip_is_a_crc_error(vector_site):
    data = sitefile.encode_site_file(vector_site)
    crc = zlib.crc32(data[HEADER_SIZE:])
    for i in range(HEADER_SIZE, len(data)):
        bad = bytearray(data)
        bad[i] ^= 0x01
        with pytest.raises(SiteFileError) as info:
            sitefile.decode_site_file(bytes(bad), "f.sfsite")
        assert info.value.kind == "crc"
        assert str(info.value).startswith(
            f"f.sfsite: CRC-32 mismatch: header says 0x{crc:08x}, payload has 0x"
        )


def test_missing_file(tmp_path):
    with pytest.raises(SiteFileError) as info:
        sitefile.read_site(tmp_path / "nope.sfsite")
    assert info.value.kind == "io"
    assert "nope.sfsite: cannot read site file" in str(info.value)


@pytest.mark.parametrize(
    "change,text",
    [
        ({"entry_ap": [0, 0, 0, 1, 1, 3, 4]}, "entry 6: ap index 4 outside 0..3"),
        ({"entry_count": [3, 4, 3, 2, 5, 1, 5]}, "entry 2: count 3 outside 1..2 (rp_scans of rp 3)"),
        (
            {"floor_height_m": [0.0, -1.0, 2.0]},
            "floor_height_m[1] = -1 not above floor_height_m[0] = 0 (heights must increase)",
        ),
        ({"rp_floor": [-2, 0, 0, 1, 1, 1]}, "rp 0: floor -2 outside -1..1"),
        (
            {"entry_std_db": [1.25, float("nan"), 2.5, 3.0, 0.5, 0.0, 1.1]},
            "entry 1: entry_std_db = nan, must be finite and >= 0",
        ),
        # finite but absurd: each outside its physical range (firmware/site_ranges.tsv)
        ({"map_rotation_deg": 3e38}, "map_rotation_deg = 3e+38 outside -360..360 deg"),
        ({"geo_rotation_deg": 720.5}, "geo_rotation_deg = 720.5 outside -360..360 deg"),
        ({"origin_alt_m": -5e6}, "origin_alt_m = -5e+06 outside -1000..10000 m"),
        ({"rp_x_m": [0.5, 2.25, 3e38, 10.125, 3.3, 7.0]}, "rp 2: rp_x_m = 3e+38 outside -100000..100000 m"),
        ({"rp_y_m": [1.0, -4.5, 0.0, 6.75, 2.2, -3e38]}, "rp 5: rp_y_m = -3e+38 outside -100000..100000 m"),
        ({"floor_height_m": [-3.5, 0.0, 1e9]}, "floor_height_m[2] = 1e+09 outside -1000..10000 m"),
        ({"fix_floor_cov_m2": [1e12, 0.0, 1.0]}, "fix_floor_cov_m2[0] = 1e+12 outside -1e+06..1e+06 m2"),
        ({"fix_bias_length_m": 1e9}, "fix_bias_length_m = 1e+09 outside 0..100000 m"),
        ({"cell_size_m": 1e30}, "cell_size_m = 1e+30 outside 0..1000 m"),
        ({"rp_scans": [3, 4, 1, 2, 5, 2_000_000_000]}, "rp 5: rp_scans = 2e+09 outside 1..1e+06"),
        (
            {"entry_mean_dbm": [-45.5, -60.25, -70.1, 500.0, -55.5, -90.0, -33.3]},
            "entry 3: entry_mean_dbm = 500 outside -150..30 dBm",
        ),
        ({"wall_x1_m": [10.0, 1e7, -2.5]}, "wall 1: wall_x1_m = 1e+07 outside -100000..100000 m"),
        ({"port_radius_m": [0.75, 1e5]}, "port 1: port_radius_m = 100000 outside 0..1000 m"),
        (
            {"beacon_rssi_1m_dbm": [float("nan"), -61.5, 200.0]},
            "beacon 2: beacon_rssi_1m_dbm = 200 outside -150..30 dBm",
        ),
        ({"ble_path_loss_exponent": 50.0}, "ble_path_loss_exponent = 50 outside 0..10"),
        (
            {"outline_y_m": [-5.0, -5.0, 8.0, 8.0, 0.0, -3e38, 7.5]},
            "outline vertex 5: outline_y_m = -3e+38 outside -100000..100000 m",
        ),
        ({"port_steps": [0, 30000]}, "port 1: port_steps = 30000 outside 0..1000 steps"),
        ({"port_hi_y_m": [0.0, 2e5]}, "port 1: port_hi_y_m = 200000 outside -100000..100000 m"),
        ({"context_cdd_min_hits": [1, 2, 5000]}, "context 2: context_cdd_min_hits = 5000 outside 1..1000"),
        ({"cdd_min_dbm": [-62.5, 99.0, -75.25]}, "cdd 1: cdd_min_dbm = 99 outside -150..30 dBm"),
        (
            {
                "lowest_floor": -100,
                "rp_floor": [-100] * 6,
                "wall_floor": [-100] * 3,
                "port_floor_lo": [-100, -100],
                "port_floor_hi": [-100, -98],
                "beacon_floor": [-100] * 3,
                "context_floor": [-100, -100, -99],
            },
            "lowest_floor = -100 outside -50..200",
        ),
        # a door's steps: the controller refuses them, so the writer and both readers do
        (
            {"port_steps": [5, 24]},
            "port 0: a door with port_steps 5 (steps are a staircase's: 0 for doors and elevators)",
        ),
    ],
)
def test_validate_names_the_field(vector_site, change, text):
    for name, value in change.items():
        setattr(vector_site, name, value)
    with pytest.raises(sitefile.SiteValidationError) as info:
        sitefile.validate_site(vector_site)
    assert str(info.value) == text


def test_array_length_must_match_count(vector_site):
    vector_site.rp_y_m = vector_site.rp_y_m[:-1]
    with pytest.raises(sitefile.SiteValidationError, match="rp_y_m has 5 values but n_rp = 6"):
        sitefile.validate_site(vector_site)


def test_too_many_floors_is_refused_naming_the_count():
    # more floors than the firmware's floor model holds (SF_FLOOR_CAPACITY): refused when written
    site = sitefile.new_site(floor_height_m=[3.0 * f for f in range(65)])
    with pytest.raises(sitefile.SiteValidationError, match=r"^n_floors = 65 outside 1\.\.64$"):
        sitefile.validate_site(site)


def test_a_door_with_steps_is_not_written(tmp_path, vector_site):
    vector_site.port_steps = [5, 24]
    with pytest.raises(sitefile.SiteFileError) as info:
        sitefile.write_site(tmp_path / "s.sfsite", vector_site)
    assert info.value.kind == "field" and "port 0: a door with port_steps 5" in str(info.value)
    assert not (tmp_path / "s.sfsite").exists()
