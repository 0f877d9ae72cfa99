#!/usr/bin/env python3
"""Writes site-file test vectors with the analyzer's writer (the reference) for tests/c/test_site.c.

Usage: gen_site_vectors.py OUT_DIR [IMPORT_DIR ...]

IMPORT_DIRs are put first on sys.path (the build's lcmtypes/python and the source analyzer/), so the
script runs from a fresh build without an installed package. Writes into OUT_DIR:

* ``site.sfsite`` — the small known site of :func:`vector_site`, written by ``sitefile.write_site``;
* ``site.txt`` — its values as read back by ``sitefile.read_site``, one field per line:
  ``<field> <value> [<value> ...]`` (strings: the rest of the line; floats by repr(), which round-trips
  a double, and float32 values are exact doubles); ``site_v2.txt`` the same for the version-2 fields
  (geo altitude and rotation, walls, ports, beacons; NaN as ``nan``), read by tests/c/test_site_v2.c;
  ``site_v3.txt`` the same for the version-3 fields (the context map; ``building_name`` as names
  separated by spaces), read by tests/c/test_site_v3.c;
* ``variants/<name>.sfsite`` — corrupted or invalid files, and ``variants.txt`` with one line each:
  ``<name>\\t<kind>\\t<exact|contains>\\t<text>``: the reader must reject the file with the ``kind``
  (``field`` → SF_ERANGE, any other → SF_ESYNTAX) and a message equal to (``exact``) or containing
  (``contains``) ``<path>: <text>``. ``exact`` texts are the Python reader's own messages, so the C
  and Python readers are held to the same words.

tests/python/sitefile/ imports this module for the same variants.
"""

from __future__ import annotations

import os
import struct
import sys
import zlib

if __name__ == "__main__":
    for _d in reversed(sys.argv[2:]):
        sys.path.insert(0, _d)

from stridefix import fix_t, pose_t, site_t, truth_t  # noqa: E402
from stridefix_analyzer.io import site_v2, site_v3, sitefile  # noqa: E402

_SCALAR_FIELDS = (
    "name",
    "source",
    "map_rotation_deg",
    "has_geo",
    "origin_lat_deg",
    "origin_lon_deg",
    "lowest_floor",
    "cell_size_m",
    "has_fix_model",
    "fix_bias_sigma_m",
    "fix_bias_length_m",
    "fix_white_share",
)
_V2_SCALAR_FIELDS = site_v2.V2_SCALARS
_V2_ARRAY_FIELDS = tuple(name for arrays in site_v2.V2_ARRAYS.values() for name in arrays)
_V3_ARRAY_FIELDS = tuple(name for arrays in site_v3.V3_ARRAYS.values() for name in arrays)
_ARRAY_FIELDS = (
    "floor_height_m",
    "ap_bssid",
    "rp_x_m",
    "rp_y_m",
    "rp_floor",
    "rp_scans",
    "entry_ap",
    "entry_rp",
    "entry_mean_dbm",
    "entry_std_db",
    "entry_count",
    "fix_floor_cov_m2",
    "fix_cov_per_acc2",
)


def vector_site() -> site_t:
    """A small site touching every corner: a negative lowest floor, geo-reference, BSSIDs at both
    ends of the 48-bit range, an AP with no entry (AP 2) and an RP with none (RP 5); walls on two
    floors, a door and stairs over three floors, beacons at both ends of the id range, one with its
    own RSSI at 1 m and the others NaN (the site's); two buildings (a square and a triangle), the door
    leading outdoors, the stairs with steps and endpoints, a link between them, three contexts
    (outdoor by GNSS, a Wi-Fi floor of A with two APs, a BLE floor of B with one beacon)."""
    return sitefile.new_site(
        name="vector site \u00fc",
        source="tests/vectors/gen_site_vectors.py",
        map_rotation_deg=12.5,
        has_geo=True,
        origin_lat_deg=47.3769,
        origin_lon_deg=8.5417,
        lowest_floor=-1,
        floor_height_m=[-3.5, 0.0, 4.25],
        ap_bssid=[0x000000000001, 0x0A1B2C3D4E5F, 0xFFFFFFFFFFFE, 0xFFFFFFFFFFFF],
        cell_size_m=2.0,
        rp_x_m=[0.5, 2.25, -1.75, 10.125, 3.3, 7.0],
        rp_y_m=[1.0, -4.5, 0.0, 6.75, 2.2, -2.0],
        rp_floor=[-1, 0, 0, 1, 1, 1],
        rp_scans=[3, 4, 1, 2, 5, 2],
        entry_ap=[0, 0, 0, 1, 1, 3, 3],
        entry_rp=[0, 1, 3, 1, 4, 2, 4],
        entry_mean_dbm=[-45.5, -60.25, -70.1, -80.0, -55.5, -90.0, -33.3],
        entry_std_db=[1.25, 0.0, 2.5, 3.0, 0.5, 0.0, 1.1],
        entry_count=[3, 4, 1, 2, 5, 1, 5],
        has_fix_model=True,
        fix_floor_cov_m2=[9.0, -1.5, 12.25],
        fix_cov_per_acc2=[1.5, 0.25, 2.0],
        fix_bias_sigma_m=3.5,
        fix_bias_length_m=20.0,
        fix_white_share=0.25,
        origin_alt_m=408.5,
        geo_rotation_deg=-7.25,
        wall_x0_m=[0.0, 10.0, -2.5],
        wall_y0_m=[0.0, 0.0, 1.5],
        wall_x1_m=[10.0, 10.0, -2.5],
        wall_y1_m=[0.0, 5.0, 8.0],
        wall_floor=[0, 0, 1],
        port_kind=[site_t.PORT_DOOR, site_t.PORT_STAIRS],
        port_x_m=[5.0, 3.0],
        port_y_m=[0.0, 4.0],
        port_radius_m=[0.75, 1.5],
        port_floor_lo=[0, -1],
        port_floor_hi=[0, 1],
        beacon_id=[0x000000000000, 0xBEAC20230001, 0xFFFFFFFFFFFF],
        beacon_x_m=[1.0, 2.5, -3.0],
        beacon_y_m=[2.0, -1.25, 6.0],
        beacon_floor=[-1, 0, 1],
        beacon_rssi_1m_dbm=[float("nan"), -61.5, float("nan")],
        ble_rssi_1m_dbm=-59.0,
        ble_path_loss_exponent=2.25,
        ble_range_sigma_db=5.5,
        building_name=["A", "B"],
        outline_x_m=[0.0, 10.0, 10.0, 0.0, 20.0, 30.0, 25.0],
        outline_y_m=[-5.0, -5.0, 8.0, 8.0, 0.0, 0.0, 7.5],
        outline_building=[0, 0, 0, 0, 1, 1, 1],
        port_building=[0, 0],
        port_outdoor=[1, 0],
        port_steps=[0, 24],
        port_lo_x_m=[5.0, 2.0],
        port_lo_y_m=[0.0, 3.5],
        port_hi_x_m=[5.0, 4.0],
        port_hi_y_m=[0.0, 4.5],
        link_a=[0],
        link_b=[1],
        context_kind=[site_t.CONTEXT_OUTDOOR, site_t.CONTEXT_FLOOR, site_t.CONTEXT_FLOOR],
        context_building=[-1, 0, 1],
        context_floor=[0, 0, 1],
        context_scheme=[pose_t.SCHEME_EKF, pose_t.SCHEME_EKF, pose_t.SCHEME_PARTICLE],
        context_method=[fix_t.METHOD_GNSS, fix_t.METHOD_WIFI, fix_t.METHOD_BLE],
        context_cdd_method=[fix_t.METHOD_GNSS, fix_t.METHOD_WIFI, fix_t.METHOD_BLE],
        context_cdd_min_hits=[1, 2, 1],
        cdd_context=[1, 1, 2],
        cdd_id=[0x000000000001, 0x0A1B2C3D4E5F, 0xBEAC20230001],
        cdd_min_dbm=[-62.5, -70.0, -75.25],
    )


def frame(
    payload: bytes, magic=sitefile.MAGIC, version=sitefile.FORMAT_VERSION, length=None, crc=None, reserved=0
) -> bytes:
    """Header (any field overridable) + payload."""
    length = len(payload) if length is None else length
    crc = zlib.crc32(payload) if crc is None else crc
    return sitefile.HEADER.pack(magic, version, length, crc, reserved) + payload


def _edited(**changes) -> bytes:
    """The vector site with fields changed, framed with a valid header (bypassing validation)."""
    s = vector_site()
    for name, value in changes.items():
        setattr(s, name, value)
    sitefile.set_counts(s)
    return frame(s.encode())


def _count_offset(s: site_t, field: str) -> int:
    """Byte offset of the int32 count ``field`` in ``s.encode()`` (site_t.lcm field order)."""
    at = 8 + 4 + len(s.name.encode()) + 1 + 4 + len(s.source.encode()) + 1 + 8 + 1 + 8 + 8 + 2
    if field == "n_floors":
        return at
    at += 4 + 8 * s.n_floors
    if field == "n_ap":
        return at
    at += 4 + 8 * s.n_ap + 4
    if field == "n_rp":
        return at
    at += 4 + 14 * s.n_rp
    if field == "n_entries":
        return at
    raise KeyError(field)


def _with_count(field: str, value: int) -> bytes:
    """The vector site's payload with the int32 count ``field`` overwritten (valid CRC)."""
    s = vector_site()
    payload = bytearray(s.encode())
    at = _count_offset(s, field)
    assert struct.unpack_from(">i", payload, at)[0] == getattr(s, field)
    payload[at : at + 4] = struct.pack(">i", value)
    return frame(bytes(payload))


def variants() -> list[tuple[str, bytes, str, str | None]]:
    """(name, file bytes, kind, C-only text or None) of every invalid file.

    For C-only text None, the expected message is the Python reader's (``exact``); otherwise the C
    message must contain that text and the Python reader must fail with ``kind``.
    """
    good = sitefile.encode_site_file(vector_site())
    payload = good[sitefile.HEADER_SIZE :]
    flipped = bytearray(good)
    flipped[sitefile.HEADER_SIZE + len(payload) // 2] ^= 0x10
    truth = truth_t()
    out = [
        ("magic", frame(payload, magic=b"SFSITX\0\x01"), "magic", None),
        ("magic_zero", frame(payload, magic=bytes(8)), "magic", None),
        ("version", frame(payload, version=4), "version", None),
        ("version_1", frame(payload, version=1), "version", None),
        ("version_2", frame(payload, version=2), "version", None),
        ("reserved", frame(payload, reserved=7), "reserved", None),
        ("length_long", frame(payload, length=len(payload) + 1), "length", None),
        ("length_short", frame(payload, length=len(payload) - 3), "length", None),
        ("length_huge", frame(payload, length=0xFFFFFFFF), "length", None),
        ("crc_header", frame(payload, crc=zlib.crc32(payload) ^ 1), "crc", None),
        ("crc_payload_flip", bytes(flipped), "crc", None),
        ("wrong_type", frame(truth.encode()), "decode", None),
        ("trailing_payload", frame(payload + b"\0\0\0\0"), "decode", None),
        ("huge_count", _with_count("n_rp", 0x20000000), "decode", "n_rp = 536870912 needs"),
        ("negative_count", _with_count("n_entries", -1), "decode", "n_entries = -1 is negative"),
        ("rp_index", _edited(entry_rp=[0, 1, 300, 1, 4, 2, 4]), "field", None),
        ("ap_index", _edited(entry_ap=[0, 0, 0, 1, 1, 3, 4]), "field", None),
        ("ap_index_negative", _edited(entry_ap=[-1, 0, 0, 1, 1, 3, 3]), "field", None),
        ("entries_unsorted", _edited(entry_ap=[0, 0, 1, 0, 1, 3, 3]), "field", None),
        ("entries_duplicate", _edited(entry_rp=[0, 1, 1, 1, 4, 2, 4]), "field", None),
        ("count_above_scans", _edited(entry_count=[3, 5, 1, 2, 5, 1, 5]), "field", None),
        ("count_zero", _edited(entry_count=[3, 4, 1, 0, 5, 1, 5]), "field", None),
        (
            "mean_inf",
            _edited(entry_mean_dbm=[-45.5, float("inf"), -70.1, -80, -55.5, -90, -33.3]),
            "field",
            None,
        ),
        ("std_negative", _edited(entry_std_db=[1.25, 0.0, -2.5, 3.0, 0.5, 0.0, 1.1]), "field", None),
        ("bssid_order", _edited(ap_bssid=[1, 0xFFFFFFFFFFFE, 0x0A1B2C3D4E5F, 0xFFFFFFFFFFFF]), "field", None),
        ("bssid_range", _edited(ap_bssid=[1, 2, 3, 1 << 48]), "field", None),
        ("floor_heights", _edited(floor_height_m=[-3.5, 0.0, 0.0]), "field", None),
        ("no_floors", _edited(floor_height_m=[]), "field", None),
        ("rp_floor", _edited(rp_floor=[-1, 0, 0, 1, 2, 1]), "field", None),
        ("rp_scans_zero", _edited(rp_scans=[3, 4, 1, 2, 5, 0]), "field", None),
        ("rp_position_inf", _edited(rp_x_m=[0.5, 2.25, float("-inf"), 10.125, 3.3, 7.0]), "field", None),
        ("cell_negative", _edited(cell_size_m=-1.0), "field", None),
        ("rotation_inf", _edited(map_rotation_deg=float("inf")), "field", None),
        ("latitude", _edited(origin_lat_deg=91.0), "field", None),
        ("fix_model_not_pd", _edited(fix_cov_per_acc2=[1.0, 2.0, 1.0]), "field", None),
        ("fix_floor_not_psd", _edited(fix_floor_cov_m2=[1.0, 0.0, -1.0]), "field", None),
        ("fix_bias_negative", _edited(fix_bias_sigma_m=-1.0), "field", None),
        ("fix_length_zero", _edited(fix_bias_length_m=0.0), "field", None),
        ("fix_white_share", _edited(fix_white_share=1.5), "field", None),
        *v2_variants(),
        *v3_variants(),
        *range_variants(),
    ]
    return out


def range_variants() -> list[tuple[str, bytes, str, str | None]]:
    """Finite but absurd values, one per row kind of firmware/site_ranges.tsv (scalars, per-element
    arrays with and without a label, the conditional ones), and a door with steps."""
    far, rp_x = 3e38, [0.5, 2.25, -1.75, 10.125, 3.3, 7.0]
    return [
        ("range_rotation", _edited(map_rotation_deg=far), "field", None),
        ("range_geo_rotation", _edited(geo_rotation_deg=-1e6), "field", None),
        ("range_altitude", _edited(origin_alt_m=-5e6), "field", None),
        ("range_fix_floor_cov", _edited(fix_floor_cov_m2=[1e12, 0.0, 1.0]), "field", None),
        ("range_fix_bias_sigma", _edited(fix_bias_sigma_m=1e9), "field", None),
        ("range_floor_height", _edited(floor_height_m=[-3.5, 0.0, 1e9]), "field", None),
        ("range_cell", _edited(cell_size_m=1e30), "field", None),
        ("range_rp_x", _edited(rp_x_m=rp_x[:2] + [far] + rp_x[3:]), "field", None),
        ("range_rp_y", _edited(rp_y_m=[1.0, -4.5, 0.0, 6.75, 2.2, -far]), "field", None),
        ("range_rp_scans", _edited(rp_scans=[3, 4, 1, 2, 5, 2_000_000_000]), "field", None),
        (
            "range_entry_mean",
            _edited(entry_mean_dbm=[-45.5, -60.25, -70.1, 500.0, -55.5, -90, -33.3]),
            "field",
            None,
        ),
        ("range_entry_std", _edited(entry_std_db=[1.25, 0.0, 2.5, 3.0, 1e9, 0.0, 1.1]), "field", None),
        ("range_wall", _edited(wall_x1_m=[10.0, 1e7, -2.5]), "field", None),
        ("range_port", _edited(port_y_m=[0.0, -1e6]), "field", None),
        ("range_port_radius", _edited(port_radius_m=[0.75, 1e5]), "field", None),
        ("range_beacon", _edited(beacon_x_m=[1.0, 2.5, far]), "field", None),
        ("range_beacon_rssi", _edited(beacon_rssi_1m_dbm=[float("nan"), -61.5, 200.0]), "field", None),
        ("range_ble_rssi", _edited(ble_rssi_1m_dbm=-1000.0), "field", None),
        ("range_ble_exponent", _edited(ble_path_loss_exponent=50.0), "field", None),
        ("range_ble_sigma", _edited(ble_range_sigma_db=1e4), "field", None),
        ("range_outline", _edited(outline_y_m=[-5.0, -5.0, 8.0, 8.0, 0.0, -far, 7.5]), "field", None),
        ("range_port_steps", _edited(port_steps=[0, 30000]), "field", None),
        ("range_port_end", _edited(port_lo_x_m=[5.0, 2e5]), "field", None),
        ("range_min_hits", _edited(context_cdd_min_hits=[1, 2, 5000]), "field", None),
        ("range_cdd_dbm", _edited(cdd_min_dbm=[-62.5, 99.0, -75.25]), "field", None),
        ("door_steps", _edited(port_steps=[5, 24]), "field", None),
    ]


def v2_variants() -> list[tuple[str, bytes, str, str | None]]:
    """One invalid file per version-2 rule (io/site_v2.py's order)."""
    nan, inf = float("nan"), float("inf")
    return [
        ("altitude_nan", _edited(origin_alt_m=nan), "field", None),
        ("geo_rotation_inf", _edited(geo_rotation_deg=-inf), "field", None),
        ("wall_inf", _edited(wall_y1_m=[0.0, inf, 8.0]), "field", None),
        ("wall_floor", _edited(wall_floor=[0, 2, 1]), "field", None),
        ("wall_zero_length", _edited(wall_x1_m=[10.0, 10.0, -2.5], wall_y1_m=[0.0, 5.0, 1.5]), "field", None),
        ("port_kind", _edited(port_kind=[1, 4]), "field", None),
        ("port_position_nan", _edited(port_x_m=[nan, 3.0]), "field", None),
        ("port_radius_zero", _edited(port_radius_m=[0.75, 0.0]), "field", None),
        ("port_floors_order", _edited(port_floor_lo=[0, 1], port_floor_hi=[0, 0]), "field", None),
        ("port_floors_range", _edited(port_floor_lo=[0, -2]), "field", None),
        ("beacon_id_range", _edited(beacon_id=[0, 0xBEAC20230001, 1 << 48]), "field", None),
        ("beacon_id_negative", _edited(beacon_id=[-1, 0xBEAC20230001, 0xFFFFFFFFFFFF]), "field", None),
        ("beacon_order", _edited(beacon_id=[0, 0xBEAC20230001, 0xBEAC20230001]), "field", None),
        ("beacon_position_inf", _edited(beacon_y_m=[2.0, inf, 6.0]), "field", None),
        ("beacon_floor", _edited(beacon_floor=[-2, 0, 1]), "field", None),
        ("beacon_rssi_inf", _edited(beacon_rssi_1m_dbm=[nan, inf, nan]), "field", None),
        ("ble_rssi_nan", _edited(ble_rssi_1m_dbm=nan), "field", None),
        ("ble_exponent_zero", _edited(ble_path_loss_exponent=0.0), "field", None),
        ("ble_sigma_negative", _edited(ble_range_sigma_db=-1.0), "field", None),
    ]


def v3_variants() -> list[tuple[str, bytes, str, str | None]]:
    """One invalid file per version-3 rule (io/site_v3.py's order)."""
    nan, inf = float("nan"), float("inf")
    kinds = [site_t.CONTEXT_OUTDOOR, site_t.CONTEXT_FLOOR, site_t.CONTEXT_FLOOR]
    return [
        ("outline_building_range", _edited(outline_building=[0, 0, 0, 0, 1, 1, 2]), "field", None),
        ("outline_inf", _edited(outline_y_m=[-5.0, -5.0, 8.0, inf, 0.0, 0.0, 7.5]), "field", None),
        ("outline_not_consecutive", _edited(outline_building=[0, 0, 1, 0, 1, 1, 1]), "field", None),
        ("outline_too_few", _edited(outline_building=[0, 0, 0, 0, 0, 1, 1]), "field", None),
        ("port_building_range", _edited(port_building=[0, 2]), "field", None),
        ("port_outdoor", _edited(port_outdoor=[2, 0]), "field", None),
        ("port_steps_negative", _edited(port_steps=[-1, 24]), "field", None),
        ("port_stairs_no_steps", _edited(port_steps=[0, 0]), "field", None),
        ("port_end_nan", _edited(port_hi_y_m=[0.0, nan]), "field", None),
        ("link_range", _edited(link_b=[2]), "field", None),
        ("link_self", _edited(link_b=[0]), "field", None),
        (
            "context_kind",
            _edited(context_kind=[site_t.CONTEXT_OUTDOOR, 4, site_t.CONTEXT_FLOOR]),
            "field",
            None,
        ),
        ("context_outdoor_building", _edited(context_building=[0, 0, 1]), "field", None),
        ("context_building_range", _edited(context_building=[-1, 0, 2]), "field", None),
        ("context_floor", _edited(context_floor=[0, 2, 1]), "field", None),
        ("context_scheme", _edited(context_scheme=[6, pose_t.SCHEME_CONTROLLER, 7]), "field", None),
        ("context_method", _edited(context_method=[2, fix_t.METHOD_LANDMARK, 4]), "field", None),
        ("context_cdd_method", _edited(context_cdd_method=[2, 1, fix_t.METHOD_PORT]), "field", None),
        ("context_min_hits", _edited(context_cdd_min_hits=[1, 0, 1]), "field", None),
        (
            "context_two_outdoor",
            _edited(
                context_kind=[site_t.CONTEXT_OUTDOOR, site_t.CONTEXT_OUTDOOR, kinds[2]],
                context_building=[-1, -1, 1],
            ),
            "field",
            None,
        ),
        ("context_duplicate", _edited(context_building=[-1, 1, 1], context_floor=[0, 1, 1]), "field", None),
        ("cdd_context_range", _edited(cdd_context=[1, 1, 3]), "field", None),
        ("cdd_order", _edited(cdd_context=[1, 2, 1]), "field", None),
        ("cdd_id_range", _edited(cdd_id=[1, 1 << 48, 5]), "field", None),
        ("cdd_dbm_inf", _edited(cdd_min_dbm=[-62.5, -inf, -75.25]), "field", None),
        ("cdd_gnss", _edited(cdd_context=[0, 1, 2]), "field", None),
    ]


def dump_v3(site: site_t) -> str:
    lines = []
    for name in _V3_ARRAY_FIELDS:
        lines.append(" ".join([name, *(v if isinstance(v, str) else repr(v) for v in getattr(site, name))]))
    return "\n".join(lines) + "\n"


def dump_v2(site: site_t) -> str:
    lines = [f"{name} {getattr(site, name)!r}" for name in _V2_SCALAR_FIELDS]
    for name in _V2_ARRAY_FIELDS:
        lines.append(" ".join([name, *(repr(v) for v in getattr(site, name))]))
    return "\n".join(lines) + "\n"


def dump(site: site_t) -> str:
    lines = []
    for name in _SCALAR_FIELDS:
        v = getattr(site, name)
        lines.append(
            f"{name} {int(v) if isinstance(v, bool) else v!r}" if not isinstance(v, str) else f"{name} {v}"
        )
    for name in _ARRAY_FIELDS:
        lines.append(" ".join([name, *(repr(v) for v in getattr(site, name))]))
    return "\n".join(lines) + "\n"


def main(out_dir: str) -> int:
    os.makedirs(os.path.join(out_dir, "variants"), exist_ok=True)
    path = os.path.join(out_dir, "site.sfsite")
    sitefile.write_site(path, vector_site())
    with open(os.path.join(out_dir, "site.txt"), "w", encoding="utf-8") as f:
        f.write(dump(sitefile.read_site(path)))
    with open(os.path.join(out_dir, "site_v2.txt"), "w", encoding="utf-8") as f:
        f.write(dump_v2(sitefile.read_site(path)))
    with open(os.path.join(out_dir, "site_v3.txt"), "w", encoding="utf-8") as f:
        f.write(dump_v3(sitefile.read_site(path)))
    rows = []
    for name, data, kind, c_text in variants():
        vpath = os.path.join(out_dir, "variants", name + ".sfsite")
        with open(vpath, "wb") as f:
            f.write(data)
        try:
            sitefile.decode_site_file(data, vpath)
        except sitefile.SiteFileError as exc:
            if exc.kind != kind:
                raise SystemExit(
                    f"variant {name}: Python reader says {exc.kind} ({exc}), want {kind}"
                ) from exc
            text = exc.reason if c_text is None else c_text
        else:
            raise SystemExit(f"variant {name}: the Python reader accepted it")
        rows.append(f"{name}\t{kind}\t{'exact' if c_text is None else 'contains'}\t{text}\n")
    with open(os.path.join(out_dir, "variants.txt"), "w", encoding="utf-8") as f:
        f.writelines(rows)
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
