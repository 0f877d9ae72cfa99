"""Radio maps: Wi-Fi scans with ground truth → a site file (the builder of ``stridefix radiomap build``).

The modules of the data flow: :mod:`.recordings` (logs → recordings on one clock), :mod:`.placement`
(each scan's position on the truth), :mod:`.survey` and :mod:`.grid` (scans → reference points),
:mod:`.assemble` (statistics → ``site_t``), :mod:`.walkstats` (walk-mode maps that add and subtract),
:mod:`.beacons` (BLE beacons and the path-loss model), :mod:`.building` (building.toml),
:mod:`.show` (summary text and plot), :mod:`.cli` (the command line).

Modes (``--mode``, default ``auto``):

* ``survey`` — one reference point (RP) per distinct surveyed position per floor (static scans whose
  positions lie within ``static_tol_m`` of the point's first scan); moving scans are skipped.
  ``cell_size_m`` = 0 in the site.
* ``walk`` — every placed scan goes to the grid cell ``(floor, ⌊x/cell⌋, ⌊y/cell⌋)`` of the map
  frame; the RP sits at the mean position of the cell's scans.
* ``auto`` — ``survey`` when at least :data:`~.survey.SURVEY_STATIC_FRACTION` of the placed scans are
  static and the static positions were scanned :data:`~.survey.SURVEY_MIN_REPEATS` times or more on
  average; otherwise ``walk``.

Per (RP, AP): mean RSSI [dBm] and population standard deviation (ddof = 0) [dB] over the scans of the
RP that heard the AP, ``count`` = those scans, ``rp_scans`` = all scans placed at the RP. A BSSID heard
twice in one scan counts once, at its strongest RSSI; incomplete scans (AP frames lost) are skipped;
entries with ``count < min_count`` are dropped, then the RPs and APs left without an entry.

Cost: O(S log S + A log A) for S scans and A AP rows; memory O(A).
"""

from __future__ import annotations

import math
import os

import numpy as np
from stridefix import site_t

from stridefix_analyzer.io.sitefile import set_counts
from stridefix_analyzer.radiomap.assemble import (
    DEFAULT_FLOOR_HEIGHT_M,
    DEFAULT_MIN_COUNT,
    TOOL_VERSION,
    assemble_site,
    site_summary,
)
from stridefix_analyzer.radiomap.beacons import site_beacons
from stridefix_analyzer.radiomap.grid import DEFAULT_CELL_SIZE_M, walk_cells
from stridefix_analyzer.radiomap.placement import (
    DEFAULT_SCAN_DURATION_MS,
    DEFAULT_STATIC_TOL_M,
    ap_rows,
    collect_scans,
)
from stridefix_analyzer.radiomap.recordings import RadioMapInputError, Recording, load_recordings
from stridefix_analyzer.radiomap.survey import SURVEY_MIN_REPEATS, SURVEY_STATIC_FRACTION, survey_points
from stridefix_analyzer.radiomap.walkstats import WalkStats

# The builder's API; realbench and callers outside the package import these names from here.
__all__ = [
    "DEFAULT_CELL_SIZE_M",
    "DEFAULT_FLOOR_HEIGHT_M",
    "DEFAULT_MIN_COUNT",
    "MODES",
    "RadioMapInputError",
    "Recording",
    "WalkStats",
    "build_site",
    "load_recordings",
]

MODES = ("auto", "survey", "walk")


def build_site(
    recordings: list[Recording],
    mode: str = "auto",
    cell_size_m: float = DEFAULT_CELL_SIZE_M,
    min_count: int = DEFAULT_MIN_COUNT,
    name: str = "",
    map_rotation_deg: float = 0.0,
    floor_height_m: float = DEFAULT_FLOOR_HEIGHT_M,
    floor_heights_m=None,
    lowest_floor: int | None = None,
    origin_deg: tuple[float, float] | None = None,
    scan_duration_ms: float = DEFAULT_SCAN_DURATION_MS,
    static_tol_m: float = DEFAULT_STATIC_TOL_M,
    beacon_table: dict[str, tuple[float, float, int]] | None = None,
) -> tuple[site_t, dict]:
    """Build a site from recordings; return (site, summary dict).

    Raises RadioMapInputError when the options are inconsistent or no scan can be placed.
    """
    if mode not in MODES:
        raise RadioMapInputError(f"mode {mode!r} not one of {MODES}")
    if not (cell_size_m > 0 and math.isfinite(cell_size_m)):
        raise RadioMapInputError(f"cell size {cell_size_m} m must be > 0")
    if min_count < 1:
        raise RadioMapInputError(f"min count {min_count} must be >= 1")
    # 1. place every scan of every recording
    placed = collect_scans(recordings, scan_duration_ms, static_tol_m)
    x, y, floor, static, ok = (placed[k] for k in ("x_m", "y_m", "floor", "static", "ok"))
    skipped, n_total = placed["skipped"], placed["n_total"]
    n_placed = int(ok.sum())
    if n_placed == 0:
        raise RadioMapInputError(
            f"none of the {n_total} scan(s) could be placed on the truth (skipped: {skipped})"
        )
    # 2. survey or walk
    static_pts = survey_points(x[ok & static], y[ok & static], floor[ok & static], static_tol_m)
    n_static = int(np.sum(ok & static))
    n_points = int(static_pts.max()) + 1 if n_static else 0
    frac = n_static / n_placed
    repeats = n_static / n_points if n_points else 0.0
    looks_survey = frac >= SURVEY_STATIC_FRACTION and repeats >= SURVEY_MIN_REPEATS
    reason = f"{frac:.0%} of placed scans static, {repeats:.1f} scans per static position"
    chosen = mode if mode != "auto" else ("survey" if looks_survey else "walk")
    scan_rp = np.full(len(x), -1, dtype=np.int64)
    if chosen == "survey":
        skipped["moving"] = int(np.sum(ok & ~static))
        use = ok & static
        if not use.any():
            raise RadioMapInputError(f"survey mode: none of the {n_placed} placed scan(s) is static")
        scan_rp[use] = static_pts
    else:
        use = ok
        scan_rp[use] = walk_cells(x[use], y[use], floor[use], cell_size_m)
    n_rp = int(scan_rp.max()) + 1
    used = np.flatnonzero(use)
    rp_scans = np.bincount(scan_rp[used], minlength=n_rp)
    rp_x = np.bincount(scan_rp[used], weights=x[used], minlength=n_rp) / rp_scans
    rp_y = np.bincount(scan_rp[used], weights=y[used], minlength=n_rp) / rp_scans
    rp_floor = np.zeros(n_rp, dtype=np.int64)
    rp_floor[scan_rp[used]] = floor[used]
    # 3. AP rows of the used scans; one per (scan, BSSID) at the strongest RSSI
    a_scan, a_bssid, a_rssi, bad_rows, duplicates = ap_rows(placed, scan_rp >= 0)
    a_rp = scan_rp[a_scan]
    # 4. per (BSSID, RP): count, mean, std (two-pass)
    keys, inverse = np.unique(np.stack([a_bssid, a_rp], axis=1), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    count = np.bincount(inverse, minlength=len(keys))
    mean = np.bincount(inverse, weights=a_rssi, minlength=len(keys)) / np.maximum(count, 1)
    var = np.bincount(inverse, weights=(a_rssi - mean[inverse]) ** 2, minlength=len(keys)) / np.maximum(
        count, 1
    )
    files = "; ".join(" + ".join(os.path.basename(f) for f in r.files) for r in recordings)
    site, kept, has_entry = assemble_site(
        keys,
        count,
        mean,
        np.sqrt(var),
        rp_x,
        rp_y,
        rp_floor,
        rp_scans,
        min_count=min_count,
        source=f"stridefix {TOOL_VERSION}: {chosen} mode from {len(recordings)} "
        f"recording(s) [{files}]; cell {cell_size_m:g} m; min count {min_count}",
        name=name,
        map_rotation_deg=map_rotation_deg,
        cell_size_m=float(cell_size_m) if chosen == "walk" else 0.0,
        floor_height_m=floor_height_m,
        floor_heights_m=floor_heights_m,
        lowest_floor=lowest_floor,
        origin_deg=origin_deg,
    )
    summary = site_summary(site)
    summary.update(
        mode=chosen,
        mode_reason=reason if mode == "auto" else f"--mode {mode} ({reason})",
        recordings=[{"name": r.name, "scans": len(r.wifi), "truth": len(r.truth)} for r in recordings],
        scans={"total": n_total, "used": int(use.sum()), **{f"skipped_{k}": v for k, v in skipped.items()}},
        ap_rows={"used": int(len(a_scan)), "duplicate_in_scan": duplicates, "invalid": bad_rows},
        entries_below_min_count=int(np.sum(~kept)),
        min_count=min_count,
        rps_dropped_no_entry=int(np.sum(~has_entry)),
    )
    # 5. BLE beacons and the path-loss model from the recordings' BLE readings (.beacons)
    ble = site_beacons(recordings, beacon_table)
    fields = ble["fields"]
    if fields:
        lo, hi = site.lowest_floor, site.lowest_floor + site.n_floors - 1
        keep = [i for i, f in enumerate(fields["beacon_floor"]) if lo <= f <= hi]
        ble["report"]["outside_site_floors"] = len(fields["beacon_id"]) - len(keep)
        for k in ("beacon_id", "beacon_x_m", "beacon_y_m", "beacon_floor", "beacon_rssi_1m_dbm"):
            fields[k] = [fields[k][i] for i in keep]
        for k, v in fields.items():
            setattr(site, k, v)
        set_counts(site)
    summary["ble"] = ble["report"]
    summary.update(n_beacons=site.n_beacons, ble_model=site_summary(site)["ble_model"])
    return site, summary
