"""The field rules of the site file's version-2 content: geo-reference, walls, ports and BLE beacons.

:func:`stridefix_analyzer.io.sitefile.validate_site` calls :func:`validate_geo` with the version-1
geo checks and :func:`validate_plan` after the radio map's entries; ``firmware/board/sf_site_v2.c``
applies the same rules in the same order with the same words. Rules, in order:

* geo (when ``has_geo``): ``origin_alt_m`` finite, ``geo_rotation_deg`` finite;
* walls: finite end points, floor within the site's floors, no zero-length segment;
* ports: kind one of ``PORT_*``, finite centre, finite radius > 0, ``floor_lo`` ≤ ``floor_hi``,
  both within the site's floors;
* beacons: ids in 0 … 2⁴⁸−1 strictly ascending, finite position, floor within the site's floors,
  ``beacon_rssi_1m_dbm`` finite or NaN (unknown); when there is a beacon, the site's model:
  ``ble_rssi_1m_dbm`` finite, ``ble_path_loss_exponent`` finite > 0, ``ble_range_sigma_db`` finite > 0.

Cost O(n_walls + n_ports + n_beacons).
"""

from __future__ import annotations

import math

import numpy as np
from stridefix import site_t

#: Port kinds (``site_t.PORT_*``) and their names in building descriptions and summaries.
PORT_KINDS = {site_t.PORT_DOOR: "door", site_t.PORT_STAIRS: "stairs", site_t.PORT_ELEVATOR: "elevator"}
BEACON_ID_LIMIT = 1 << 48


#: The version-2 fields of ``site_t``, the one list the checks, the empty content, the counts and the
#: test vectors (tests/vectors/gen_site_vectors.py) read: scalars, and each count with its arrays.
V2_SCALARS = (
    "origin_alt_m",
    "geo_rotation_deg",
    "ble_rssi_1m_dbm",
    "ble_path_loss_exponent",
    "ble_range_sigma_db",
)
V2_ARRAYS = {
    "n_walls": ("wall_x0_m", "wall_y0_m", "wall_x1_m", "wall_y1_m", "wall_floor"),
    "n_ports": ("port_kind", "port_x_m", "port_y_m", "port_radius_m", "port_floor_lo", "port_floor_hi"),
    "n_beacons": ("beacon_id", "beacon_x_m", "beacon_y_m", "beacon_floor", "beacon_rssi_1m_dbm"),
}


class SiteV2ValidationError(ValueError):
    """Base of the version-2 rule failures (sitefile re-raises them as SiteValidationError)."""


def finite(*values: float) -> bool:
    return all(math.isfinite(v) for v in values)


def check_len(
    site: site_t, count_name: str, *arrays: str, error: type[ValueError] = SiteV2ValidationError
) -> int:
    """``site.<count_name>``, after checking it is not negative and every array holds that many
    values; raises ``error`` naming the field otherwise (sitefile passes its own error class)."""
    n = getattr(site, count_name)
    if n < 0:
        raise error(f"{count_name} = {n} is negative")
    for name in arrays:
        got = len(getattr(site, name))
        if got != n:
            raise error(f"{name} has {got} values but {count_name} = {n}")
    return int(n)


def _lens(site: site_t, count_name: str) -> int:
    return check_len(site, count_name, *V2_ARRAYS[count_name])


def validate_geo(site: site_t) -> None:
    """The version-2 geo-reference rules (only called when ``has_geo``)."""
    if not finite(site.origin_alt_m):
        raise SiteV2ValidationError(f"origin_alt_m is {site.origin_alt_m:g}, must be finite")
    if not finite(site.geo_rotation_deg):
        raise SiteV2ValidationError(f"geo_rotation_deg is {site.geo_rotation_deg:g}, must be finite")


def _walls_pass(site: site_t, lowest: int, top: int) -> bool:
    """Whether every wall keeps the rules of :func:`validate_plan`, checked at once with numpy; False
    (or anything numpy cannot hold) sends the per-wall loop, which names the first one broken."""
    try:
        x0, y0, x1, y1 = (
            np.asarray(getattr(site, f), float) for f in ("wall_x0_m", "wall_y0_m", "wall_x1_m", "wall_y1_m")
        )
        f = np.asarray(site.wall_floor, np.int64)
        return bool(
            np.all(np.isfinite(x0) & np.isfinite(y0) & np.isfinite(x1) & np.isfinite(y1))
            and np.all((f >= lowest) & (f <= top))
            and not np.any((x0 == x1) & (y0 == y1))
        )
    except (TypeError, ValueError, OverflowError):
        return False


def validate_plan(site: site_t, lowest: int, top: int) -> None:
    """Walls, ports and beacons against the floors ``lowest`` … ``top``; raise on the first broken."""
    n_walls = _lens(site, "n_walls")
    for i in range(0 if _walls_pass(site, lowest, top) else n_walls):
        x0, y0, x1, y1 = site.wall_x0_m[i], site.wall_y0_m[i], site.wall_x1_m[i], site.wall_y1_m[i]
        f = site.wall_floor[i]
        if not finite(x0, y0, x1, y1):
            raise SiteV2ValidationError(
                f"wall {i}: end points ({x0:g}, {y0:g}) - ({x1:g}, {y1:g}) not finite"
            )
        if not lowest <= f <= top:
            raise SiteV2ValidationError(f"wall {i}: floor {f} outside {lowest}..{top}")
        if x0 == x1 and y0 == y1:
            raise SiteV2ValidationError(f"wall {i}: zero length at ({x0:g}, {y0:g})")
    n_ports = _lens(site, "n_ports")
    for i in range(n_ports):
        kind, x, y, r = site.port_kind[i], site.port_x_m[i], site.port_y_m[i], site.port_radius_m[i]
        lo, hi = site.port_floor_lo[i], site.port_floor_hi[i]
        if kind not in PORT_KINDS:
            raise SiteV2ValidationError(f"port {i}: kind {kind} unknown (1 door, 2 stairs, 3 elevator)")
        if not finite(x, y):
            raise SiteV2ValidationError(f"port {i}: position ({x:g}, {y:g}) not finite")
        if not (finite(r) and r > 0.0):
            raise SiteV2ValidationError(f"port {i}: port_radius_m = {r:g}, must be finite and > 0")
        if lo > hi:
            raise SiteV2ValidationError(f"port {i}: floor_lo {lo} above floor_hi {hi}")
        if lo < lowest or hi > top:
            raise SiteV2ValidationError(f"port {i}: floors {lo}..{hi} outside {lowest}..{top}")
    n_beacons = _lens(site, "n_beacons")
    for i in range(n_beacons):
        b, x, y, f = site.beacon_id[i], site.beacon_x_m[i], site.beacon_y_m[i], site.beacon_floor[i]
        if not 0 <= b < BEACON_ID_LIMIT:
            raise SiteV2ValidationError(f"beacon {i}: id {b} outside 0..2^48-1")
        if i > 0 and not b > site.beacon_id[i - 1]:
            raise SiteV2ValidationError(
                f"beacon {i}: id 0x{b:012x} not above beacon {i - 1}'s 0x{site.beacon_id[i - 1]:012x} "
                f"(ids must be strictly ascending)"
            )
        if not finite(x, y):
            raise SiteV2ValidationError(f"beacon {i}: position ({x:g}, {y:g}) not finite")
        if not lowest <= f <= top:
            raise SiteV2ValidationError(f"beacon {i}: floor {f} outside {lowest}..{top}")
        r1 = site.beacon_rssi_1m_dbm[i]
        if math.isinf(r1):
            raise SiteV2ValidationError(
                f"beacon {i}: beacon_rssi_1m_dbm is {r1:g}, must be finite or NaN (unknown)"
            )
    if n_beacons > 0:
        if not finite(site.ble_rssi_1m_dbm):
            raise SiteV2ValidationError(f"ble_rssi_1m_dbm is {site.ble_rssi_1m_dbm:g}, must be finite")
        if not (finite(site.ble_path_loss_exponent) and site.ble_path_loss_exponent > 0.0):
            raise SiteV2ValidationError(
                f"ble_path_loss_exponent = {site.ble_path_loss_exponent:g}, must be finite and > 0"
            )
        if not (finite(site.ble_range_sigma_db) and site.ble_range_sigma_db > 0.0):
            raise SiteV2ValidationError(
                f"ble_range_sigma_db = {site.ble_range_sigma_db:g}, must be finite and > 0"
            )


def init_v2_fields(s: site_t) -> None:
    """Empty version-2 content: no geo altitude or rotation, no walls, ports or beacons."""
    for name in V2_SCALARS:
        setattr(s, name, 0.0)
    for arrays in V2_ARRAYS.values():
        for name in arrays:
            setattr(s, name, [])


def set_v2_counts(s: site_t) -> None:
    for count, arrays in V2_ARRAYS.items():
        setattr(s, count, len(getattr(s, arrays[0])))
