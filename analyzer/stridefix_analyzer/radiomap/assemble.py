"""Site assembly: per-(BSSID, RP) statistics and reference points → a ``site_t``, and its summary.

Entries with ``count < min_count`` are dropped, then the RPs and APs left without an entry (an RP
with no entry tells a matcher nothing). Floors: ``lowest_floor`` .. highest RP floor
(``--lowest-floor`` may extend it down); heights ``floor × floor_height_m`` or the explicit
``--floor-heights-m`` list (one per floor from the lowest).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stridefix import site_t

from stridefix_analyzer.io.sitefile import new_site
from stridefix_analyzer.radiomap.recordings import RadioMapInputError

DEFAULT_FLOOR_HEIGHT_M = 3.5
DEFAULT_MIN_COUNT = 2
TOOL_VERSION = "radiomap 1"


def floor_heights(rp_floor: np.ndarray, lowest_floor, floor_height_m, floor_heights_m):
    lo = int(rp_floor.min())
    hi = int(rp_floor.max())
    if lowest_floor is not None:
        if lowest_floor > lo:
            raise RadioMapInputError(
                f"--lowest-floor {lowest_floor} is above floor {lo}, which has reference points"
            )
        lo = int(lowest_floor)
    if floor_heights_m is not None:
        heights = [float(h) for h in floor_heights_m]
        if lo + len(heights) - 1 < hi:
            raise RadioMapInputError(
                f"--floor-heights-m gives {len(heights)} floor(s) from "
                f"{lo}, but reference points reach floor {hi}"
            )
        if any(not b > a for a, b in zip(heights, heights[1:])):
            raise RadioMapInputError(f"--floor-heights-m {heights} must increase")
        return lo, heights
    return lo, [f * float(floor_height_m) for f in range(lo, hi + 1)]


def assemble_site(
    keys,
    count,
    mean,
    std,
    rp_x,
    rp_y,
    rp_floor,
    rp_scans,
    *,
    min_count: int,
    source: str,
    name: str,
    map_rotation_deg: float,
    cell_size_m: float,
    floor_height_m: float,
    floor_heights_m,
    lowest_floor: int | None,
    origin_deg,
) -> tuple[site_t, np.ndarray, np.ndarray]:
    """The site of per-(BSSID, RP) statistics: drop entries below ``min_count``, then the RPs left
    without an entry (the rest renumbered in order), and pack everything into a ``site_t``.

    ``keys`` (e, 2) int64 rows (BSSID, RP index) sorted lexicographically; ``count``, ``mean``,
    ``std`` (e,); ``rp_*`` (n_rp,). Returns (site, kept entries (e,) bool, RPs kept (n_rp,) bool).
    """
    n_rp = len(rp_x)
    kept = count >= min_count
    keys, count, mean, std = keys[kept].copy(), count[kept], mean[kept], std[kept]
    if len(keys) == 0:
        raise RadioMapInputError(
            f"no access point was heard in {min_count} or more scans at any "
            f"of the {n_rp} reference points (lower --min-count?)"
        )
    # an RP with no entry left tells a matcher nothing: drop it, renumber the rest in order
    has_entry = np.zeros(n_rp, dtype=bool)
    has_entry[keys[:, 1]] = True
    keys[:, 1] = (np.cumsum(has_entry) - 1)[keys[:, 1]]
    rp_x, rp_y, rp_floor, rp_scans = (v[has_entry] for v in (rp_x, rp_y, rp_floor, rp_scans))
    bssids, entry_ap = np.unique(keys[:, 0], return_inverse=True)
    lo, heights = floor_heights(rp_floor, lowest_floor, floor_height_m, floor_heights_m)
    site = new_site(
        name=name,
        source=source,
        map_rotation_deg=float(map_rotation_deg),
        has_geo=origin_deg is not None,
        origin_lat_deg=float(origin_deg[0]) if origin_deg else 0.0,
        origin_lon_deg=float(origin_deg[1]) if origin_deg else 0.0,
        lowest_floor=lo,
        floor_height_m=heights,
        ap_bssid=bssids.astype(np.int64),
        cell_size_m=float(cell_size_m),
        rp_x_m=rp_x.astype(np.float32),
        rp_y_m=rp_y.astype(np.float32),
        rp_floor=rp_floor,
        rp_scans=rp_scans,
        entry_ap=np.asarray(entry_ap).reshape(-1),
        entry_rp=keys[:, 1],
        entry_mean_dbm=mean.astype(np.float32),
        entry_std_db=std.astype(np.float32),
        entry_count=count,
    )
    return site, kept, has_entry


def site_summary(site: site_t) -> dict:
    """Counts and coverage of a site (per floor: RPs, APs heard, extent, cell area)."""
    rp_floor = np.asarray(site.rp_floor, dtype=np.int64)
    rp_x, rp_y = np.asarray(site.rp_x_m, float), np.asarray(site.rp_y_m, float)
    aps_per_rp = np.bincount(np.asarray(site.entry_rp, dtype=np.int64), minlength=site.n_rp)
    floors = {}
    for i in range(site.n_floors):
        f = site.lowest_floor + i
        sel = rp_floor == f
        entry_sel = sel[np.asarray(site.entry_rp, dtype=np.int64)] if site.n_entries else np.zeros(0, bool)
        info: dict[str, Any] = {
            "height_m": float(site.floor_height_m[i]),
            "rps": int(sel.sum()),
            "aps": int(len(set(np.asarray(site.entry_ap)[entry_sel].tolist()))),
        }
        if sel.any():
            info.update(
                x_range_m=[float(rp_x[sel].min()), float(rp_x[sel].max())],
                y_range_m=[float(rp_y[sel].min()), float(rp_y[sel].max())],
                mean_aps_per_rp=float(aps_per_rp[sel].mean()),
                mean_scans_per_rp=float(np.mean(np.asarray(site.rp_scans)[sel])),
            )
            if site.cell_size_m > 0:
                info["cell_area_m2"] = float(sel.sum() * site.cell_size_m**2)
        floors[f] = info
    return {
        "name": site.name,
        "source": site.source,
        "n_rp": site.n_rp,
        "n_ap": site.n_ap,
        "n_entries": site.n_entries,
        "n_floors": site.n_floors,
        "lowest_floor": site.lowest_floor,
        "cell_size_m": float(site.cell_size_m),
        "map_rotation_deg": site.map_rotation_deg,
        "geo": [site.origin_lat_deg, site.origin_lon_deg] if site.has_geo else None,
        "rps_without_ap": int(np.sum(aps_per_rp == 0)),
        "floors": floors,
        "n_walls": site.n_walls,
        "n_ports": site.n_ports,
        "n_beacons": site.n_beacons,
        "ble_model": [site.ble_rssi_1m_dbm, site.ble_path_loss_exponent, site.ble_range_sigma_db]
        if site.n_beacons
        else None,
    }
