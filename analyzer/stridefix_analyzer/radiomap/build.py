"""Radio maps: Wi-Fi scans with ground truth → a site file (``stridefix radiomap build|show``).

Input: LCM logs with ``WIFI`` (scans) and ``TRUTH`` (positions). Logs are grouped into *recordings*
that share a clock: an argument ``a.lcmlog,b.lcmlog`` is one recording of those files; a plain
argument holding both WIFI and TRUTH is a recording by itself; the remaining plain arguments (e.g. the
simulator's firmware log and its truth log) are merged into one recording.

Placing a scan (time ``t`` = scan start [µs], the position the simulator measures at): truth is
interpolated linearly in time between the samples around ``t`` (sparse waypoints work); a scan outside
the truth's time span, or between two samples on different floors, is skipped and counted. A scan is
*static* when every truth sample from the last one at or before ``t`` to the first one at or after
``t + scan_duration`` is within ``static_tol_m`` of the first and on the same floor.

Modes (``--mode``, default ``auto``):

* ``survey`` — one reference point (RP) per distinct surveyed position per floor (static scans whose
  positions lie within ``static_tol_m`` of the point's first scan); moving scans are skipped.
  ``cell_size_m`` = 0 in the site.
* ``walk`` — every placed scan goes to the grid cell ``(floor, ⌊x/cell⌋, ⌊y/cell⌋)`` of the map
  frame; the RP sits at the mean position of the cell's scans.
* ``auto`` — ``survey`` when at least :data:`SURVEY_STATIC_FRACTION` of the placed scans are static
  and the static positions were scanned :data:`SURVEY_MIN_REPEATS` times or more on average;
  otherwise ``walk``.

Per (RP, AP): mean RSSI [dBm] and population standard deviation (ddof = 0) [dB] over the scans of the
RP that heard the AP, ``count`` = those scans, ``rp_scans`` = all scans placed at the RP. A BSSID heard
twice in one scan counts once, at its strongest RSSI; incomplete scans (AP frames lost) are skipped;
entries with ``count < min_count`` are dropped, then the RPs and APs left without an entry (an RP
with no entry tells a matcher nothing).

Floors: ``lowest_floor`` .. highest RP floor (``--lowest-floor`` may extend it down); heights
``floor × floor_height_m`` or the explicit ``--floor-heights-m`` list (one per floor from the lowest).

Cost: O(S log S + A log A) for S scans and A AP rows; memory O(A).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import warnings

import numpy as np
from stridefix import site_t

from stridefix_analyzer.io.logread import LogData, LogReadError, LogTruncatedWarning, Table, read_logs
from stridefix_analyzer.io.sitefile import SiteFileError, new_site, read_site, write_site

MODES = ("auto", "survey", "walk")
DEFAULT_CELL_SIZE_M = 2.0
DEFAULT_FLOOR_HEIGHT_M = 3.5
DEFAULT_MIN_COUNT = 2
DEFAULT_STATIC_TOL_M = 0.05
DEFAULT_SCAN_DURATION_MS = 0
#: auto mode: share of placed scans that must be static for a survey
SURVEY_STATIC_FRACTION = 0.8
#: auto mode: mean scans per surveyed position for a survey
SURVEY_MIN_REPEATS = 2.0
TOOL_VERSION = "radiomap 1"

_BSSID_LIMIT = 1 << 48


class RadioMapInputError(Exception):
    """The logs cannot make a radio map (no WIFI or TRUTH, no scan placed, bad options)."""


# --- recordings ----------------------------------------------------------------------------------


class Recording:
    """One set of logs on one clock: WIFI scans, their APs and TRUTH, sorted by time."""

    def __init__(self, files: list[str], wifi: Table, wifi_ap: Table, truth: Table):
        self.files, self.wifi, self.wifi_ap, self.truth = list(files), wifi, wifi_ap, truth
        self.name = " + ".join(self.files)


def _read_one(path: str) -> LogData:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        return read_logs([path], decode=("WIFI", "TRUTH"))


def _merge(files: list[str], datas: list[LogData]) -> Recording:
    """Merge the WIFI / WIFI_AP / TRUTH tables of several files into one Recording."""
    name = " + ".join(files)
    missing = [ch for ch in ("WIFI", "TRUTH") if not any(d.table(ch) for d in datas)]
    if missing:
        raise RadioMapInputError(
            f"{name}: no {' and no '.join(missing)} messages (a radio map "
            f"needs Wi-Fi scans and ground truth on the same clock)"
        )
    wifi_parts, ap_parts, truth_parts, offset = [], [], [], 0
    for d in datas:
        if d.table("WIFI"):
            w, ap = d.table("WIFI"), d.table("WIFI_AP")
            wifi_parts.append(w.to_dict())
            cols = ap.to_dict()
            cols["scan_row"] = cols["scan_row"] + offset
            ap_parts.append(cols)
            offset += len(w)
        if d.table("TRUTH"):
            truth_parts.append(d.table("TRUTH").to_dict())

    def cat(parts):
        return Table({k: np.concatenate([p[k] for p in parts]) for k in parts[0]})

    wifi, wifi_ap, truth = cat(wifi_parts), cat(ap_parts), cat(truth_parts).sorted_by("t_us")
    order = np.argsort(wifi["t_us"], kind="stable")
    renumber = np.empty(len(order), dtype=np.int64)
    renumber[order] = np.arange(len(order))
    wifi = wifi.rows(order)
    cols = wifi_ap.to_dict()
    cols["scan_row"] = renumber[cols["scan_row"]]
    return Recording(files, wifi, Table(cols), truth)


def load_recordings(args: list[str]) -> list[Recording]:
    """Group log arguments into recordings (see the module docstring) and read them.

    Raises LogReadError (a file unreadable) or RadioMapInputError (a recording lacks WIFI/TRUTH).
    """
    recordings, rest = [], []
    for arg in args:
        files = [f for f in str(arg).split(",") if f]
        datas = [_read_one(f) for f in files]
        if len(files) > 1 or (datas[0].table("WIFI") and datas[0].table("TRUTH")):
            recordings.append(_merge(files, datas))
        else:
            rest.append((files[0], datas[0]))
    if rest:
        recordings.append(_merge([f for f, _ in rest], [d for _, d in rest]))
    return recordings


# --- placing scans -------------------------------------------------------------------------------

# reasons a scan is not used
SKIP_REASONS = ("incomplete", "outside_truth", "floor_change", "moving")


def place_scans(
    rec: Recording, scan_duration_us: int = 0, static_tol_m: float = DEFAULT_STATIC_TOL_M
) -> dict[str, np.ndarray]:
    """Position, floor and static flag of each scan of ``rec``.

    Returns
    -------
    dict of str to ndarray, each shape (n_scans,)
        ``x_m``, ``y_m`` (interpolated truth, NaN when not placed), ``floor`` (int), ``static``
        (bool), ``skip`` (int: 0 placed, else 1 + index in :data:`SKIP_REASONS` except ``moving``).
    """
    t = rec.wifi["t_us"].astype(np.int64)
    tt = rec.truth["t_us"].astype(np.int64)
    tx, ty, tf = rec.truth["x_m"], rec.truth["y_m"], rec.truth["floor"].astype(np.int64)
    n = len(t)
    x, y = np.full(n, np.nan), np.full(n, np.nan)
    floor = np.zeros(n, dtype=np.int64)
    static = np.zeros(n, dtype=bool)
    skip = np.zeros(n, dtype=np.int64)
    skip[~rec.wifi["complete"]] = 1 + SKIP_REASONS.index("incomplete")
    i0 = np.searchsorted(tt, t, side="right") - 1  # last truth at or before t
    i_end = np.searchsorted(tt, t + scan_duration_us, side="left")  # first at or after t + dur
    for k in range(n):
        if skip[k]:
            continue
        a = i0[k]
        if a < 0 or t[k] > tt[-1]:
            skip[k] = 1 + SKIP_REASONS.index("outside_truth")
            continue
        if tt[a] == t[k] or a + 1 >= len(tt):
            x[k], y[k], floor[k] = tx[a], ty[a], tf[a]
        else:
            b = a + 1
            if tf[a] != tf[b]:
                skip[k] = 1 + SKIP_REASONS.index("floor_change")
                continue
            w = (t[k] - tt[a]) / (tt[b] - tt[a])
            x[k], y[k], floor[k] = tx[a] + w * (tx[b] - tx[a]), ty[a] + w * (ty[b] - ty[a]), tf[a]
        last = min(max(i_end[k], a), len(tt) - 1)
        span = slice(a, last + 1)
        static[k] = bool(
            np.all(np.hypot(tx[span] - tx[a], ty[span] - ty[a]) <= static_tol_m) and np.all(tf[span] == tf[a])
        )
    return {"x_m": x, "y_m": y, "floor": floor, "static": static, "skip": skip}


def _survey_points(x, y, floor, tol_m: float) -> np.ndarray:
    """Cluster index per scan: a scan joins the first point of its floor within tol_m of that
    point's first scan, else starts a new point (points numbered in order of first scan)."""
    ids = np.empty(len(x), dtype=np.int64)
    anchors: list[tuple[int, float, float]] = []
    for k in range(len(x)):
        for j, (f, ax, ay) in enumerate(anchors):
            if f == floor[k] and math.hypot(x[k] - ax, y[k] - ay) <= tol_m:
                ids[k] = j
                break
        else:
            ids[k] = len(anchors)
            anchors.append((int(floor[k]), float(x[k]), float(y[k])))
    return ids


def _walk_cells(x, y, floor, cell_m: float) -> np.ndarray:
    """Cell id per scan, ids ordered by (floor, iy, ix)."""
    key = np.stack(
        [floor, np.floor(y / cell_m).astype(np.int64), np.floor(x / cell_m).astype(np.int64)], axis=1
    )
    _, ids = np.unique(key, axis=0, return_inverse=True)
    return ids.reshape(-1)


# --- building ------------------------------------------------------------------------------------


def _floors(rp_floor: np.ndarray, lowest_floor, floor_height_m, floor_heights_m):
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


def _collect_scans(recordings: list[Recording], scan_duration_ms: float, static_tol_m: float) -> dict:
    """Place every scan of every recording (:func:`place_scans`) and pool their AP rows.

    Returns
    -------
    dict
        Per scan (n,): ``x_m``, ``y_m``, ``floor``, ``static``, ``ok`` (placed), ``rec`` (index of
        its recording); per AP row (a,): ``ap_scan`` (pooled scan index), ``ap_bssid``,
        ``ap_rssi``; ``skipped`` (count per :data:`SKIP_REASONS`), ``n_total`` (scans).
    """
    xs, ys, fs, st, scan_ok, recs, ap_scan, ap_bssid, ap_rssi = ([] for _ in range(9))
    skipped = dict.fromkeys(SKIP_REASONS, 0)
    n_total, base = 0, 0
    for r, rec in enumerate(recordings):
        p = place_scans(rec, int(round(scan_duration_ms * 1000)), static_tol_m)
        for i, reason in enumerate(SKIP_REASONS):
            skipped[reason] += int(np.sum(p["skip"] == i + 1))
        xs.append(p["x_m"]), ys.append(p["y_m"]), fs.append(p["floor"]), st.append(p["static"])
        scan_ok.append(p["skip"] == 0)
        recs.append(np.full(len(rec.wifi), r, dtype=np.int64))
        ap_scan.append(rec.wifi_ap["scan_row"] + base)
        ap_bssid.append(rec.wifi_ap["bssid"]), ap_rssi.append(rec.wifi_ap["rssi_dbm"])
        base += len(rec.wifi)
        n_total += len(rec.wifi)

    def cat(parts, dtype):
        return np.concatenate(parts).astype(dtype) if parts else np.zeros(0, dtype)

    return {
        "x_m": cat(xs, float),
        "y_m": cat(ys, float),
        "floor": cat(fs, np.int64),
        "static": cat(st, bool),
        "ok": cat(scan_ok, bool),
        "rec": cat(recs, np.int64),
        "ap_scan": cat(ap_scan, np.int64),
        "ap_bssid": cat(ap_bssid, np.int64),
        "ap_rssi": cat(ap_rssi, float),
        "skipped": skipped,
        "n_total": n_total,
    }


def _ap_rows(placed: dict, scan_used: np.ndarray):
    """AP rows of the used scans, one per (scan, BSSID) at the strongest RSSI, sorted by (scan,
    BSSID); rows with a non-finite RSSI or a BSSID outside 0..2⁴⁸−1 are dropped.

    Returns (a_scan, a_bssid, a_rssi, invalid rows, duplicate rows).
    """
    a_scan, a_bssid, a_rssi = placed["ap_scan"], placed["ap_bssid"], placed["ap_rssi"]
    used = scan_used[a_scan]
    keep = used & np.isfinite(a_rssi) & (a_bssid >= 0) & (a_bssid < _BSSID_LIMIT)
    bad_rows = int(np.sum(used & ~keep))
    a_scan, a_bssid, a_rssi = a_scan[keep], a_bssid[keep], a_rssi[keep]
    order = np.lexsort((-a_rssi, a_bssid, a_scan))
    a_scan, a_bssid, a_rssi = a_scan[order], a_bssid[order], a_rssi[order]
    first = np.ones(len(a_scan), dtype=bool)
    first[1:] = (a_scan[1:] != a_scan[:-1]) | (a_bssid[1:] != a_bssid[:-1])
    duplicates = int(np.sum(~first))
    return a_scan[first], a_bssid[first], a_rssi[first], bad_rows, duplicates


def _assemble_site(
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
    lo, heights = _floors(rp_floor, lowest_floor, floor_height_m, floor_heights_m)
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
    placed = _collect_scans(recordings, scan_duration_ms, static_tol_m)
    x, y, floor, static, ok = (placed[k] for k in ("x_m", "y_m", "floor", "static", "ok"))
    skipped, n_total = placed["skipped"], placed["n_total"]
    n_placed = int(ok.sum())
    if n_placed == 0:
        raise RadioMapInputError(
            f"none of the {n_total} scan(s) could be placed on the truth (skipped: {skipped})"
        )
    # 2. survey or walk
    static_pts = _survey_points(x[ok & static], y[ok & static], floor[ok & static], static_tol_m)
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
        scan_rp[use] = _walk_cells(x[use], y[use], floor[use], cell_size_m)
    n_rp = int(scan_rp.max()) + 1
    used = np.flatnonzero(use)
    rp_scans = np.bincount(scan_rp[used], minlength=n_rp)
    rp_x = np.bincount(scan_rp[used], weights=x[used], minlength=n_rp) / rp_scans
    rp_y = np.bincount(scan_rp[used], weights=y[used], minlength=n_rp) / rp_scans
    rp_floor = np.zeros(n_rp, dtype=np.int64)
    rp_floor[scan_rp[used]] = floor[used]
    # 3. AP rows of the used scans; one per (scan, BSSID) at the strongest RSSI
    a_scan, a_bssid, a_rssi, bad_rows, duplicates = _ap_rows(placed, scan_rp >= 0)
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
    site, kept, has_entry = _assemble_site(
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
    return site, summary


# --- walk-mode sufficient statistics (leave-one-walk-out maps) -----------------------------------


def _group_sum(keys: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``keys`` (n, k) int64 made unique (sorted lexicographically, as ``np.unique(...,
    axis=0)`` sorts them) and ``values`` (n, m) summed per unique row."""
    if len(keys) == 0:
        return keys.reshape(0, keys.shape[1]), values.reshape(0, values.shape[1])
    # (floor, iy, ix) packed into one order-preserving code: fewer sort keys
    cols = (
        [_row_codes(keys[:, :3])] + [keys[:, j] for j in range(3, keys.shape[1])]
        if keys.shape[1] >= 3
        else [keys[:, j] for j in range(keys.shape[1])]
    )
    order = np.lexsort(cols[::-1])
    sorted_cols = [c[order] for c in cols]
    diff = np.zeros(len(order), dtype=bool)
    diff[0] = True
    for c in sorted_cols:
        diff[1:] |= c[1:] != c[:-1]
    first = np.flatnonzero(diff)
    return keys[order[first]], np.add.reduceat(values[order], first, axis=0)


class WalkStats:
    """Sufficient statistics of a walk-mode radio map, which add and subtract.

    A walk-mode map is a function of per-cell and per-(cell, AP) sums, so the map of a set of
    recordings is the sum of their statistics, and the map of all recordings but one is
    ``total - that one`` (leave one walk out without rebuilding). Counts are integers and RSSI sums
    of integer dBm are exact in float64, so subtraction gives the same entries as a build from
    scratch; position sums differ from it by rounding only (~1e-12 m).

    Attributes
    ----------
    cell_size_m : float
        Grid cell [m].
    cell_key : (c, 3) int64
        (floor, iy, ix) of each cell, sorted lexicographically (= the RP order of :func:`build_site`).
    cell_scans : (c,) int64
        Scans placed in the cell.
    cell_sum_xy_m : (c, 2) float64
        Σx, Σy of those scans' positions [m].
    entry_key : (e, 4) int64
        (floor, iy, ix, BSSID), sorted.
    entry_count : (e,) int64
        Scans of the cell that heard the AP (once per scan, strongest reading).
    entry_sum_dbm, entry_sum2_dbm2 : (e,) float64
        Σ RSSI [dBm] and Σ RSSI² [dBm²] over those scans.
    scans : dict
        ``total``, ``used`` and ``skipped_<reason>`` counts (add and subtract like the rest).
    """

    def __init__(
        self,
        cell_size_m,
        cell_key,
        cell_scans,
        cell_sum_xy_m,
        entry_key,
        entry_count,
        entry_sum_dbm,
        entry_sum2_dbm2,
        scans,
    ):
        self.cell_size_m = float(cell_size_m)
        self.cell_key, self.cell_scans, self.cell_sum_xy_m = cell_key, cell_scans, cell_sum_xy_m
        self.entry_key, self.entry_count = entry_key, entry_count
        self.entry_sum_dbm, self.entry_sum2_dbm2 = entry_sum_dbm, entry_sum2_dbm2
        self.scans = dict(scans)

    @classmethod
    def from_recordings(
        cls,
        recordings: list[Recording],
        cell_size_m: float = DEFAULT_CELL_SIZE_M,
        scan_duration_ms: float = DEFAULT_SCAN_DURATION_MS,
        static_tol_m: float = DEFAULT_STATIC_TOL_M,
    ) -> "WalkStats":
        """Statistics of ``recordings`` placed and deduplicated exactly as :func:`build_site` does
        in walk mode. A recording with no placeable scan contributes nothing (no error)."""
        if not (cell_size_m > 0 and math.isfinite(cell_size_m)):
            raise RadioMapInputError(f"cell size {cell_size_m} m must be > 0")
        placed = _collect_scans(recordings, scan_duration_ms, static_tol_m)
        ok = placed["ok"]
        x, y, floor = placed["x_m"], placed["y_m"], placed["floor"]
        key = np.zeros((len(x), 3), dtype=np.int64)
        key[ok] = np.stack(
            [
                floor[ok],
                np.floor(y[ok] / cell_size_m).astype(np.int64),
                np.floor(x[ok] / cell_size_m).astype(np.int64),
            ],
            axis=1,
        )
        cell_key, cell_vals = _group_sum(key[ok], np.column_stack([np.ones(int(ok.sum())), x[ok], y[ok]]))
        a_scan, a_bssid, a_rssi, _, _ = _ap_rows(placed, ok)
        ekey = np.column_stack([key[a_scan], a_bssid]) if len(a_scan) else np.zeros((0, 4), np.int64)
        entry_key, evals = _group_sum(ekey, np.column_stack([np.ones(len(a_rssi)), a_rssi, a_rssi**2]))
        scans = {
            "total": placed["n_total"],
            "used": int(ok.sum()),
            **{f"skipped_{k}": v for k, v in placed["skipped"].items() if k != "moving"},
        }
        return cls(
            cell_size_m,
            cell_key,
            np.rint(cell_vals[:, 0]).astype(np.int64),
            cell_vals[:, 1:].copy(),
            entry_key,
            np.rint(evals[:, 0]).astype(np.int64),
            evals[:, 1].copy(),
            evals[:, 2].copy(),
            scans,
        )

    @classmethod
    def empty(cls, cell_size_m: float = DEFAULT_CELL_SIZE_M) -> "WalkStats":
        return cls(
            cell_size_m,
            np.zeros((0, 3), np.int64),
            np.zeros(0, np.int64),
            np.zeros((0, 2)),
            np.zeros((0, 4), np.int64),
            np.zeros(0, np.int64),
            np.zeros(0),
            np.zeros(0),
            {},
        )

    @classmethod
    def total(cls, parts: list["WalkStats"]) -> "WalkStats":
        """The sum of many statistics at once (one sort instead of one per addition)."""
        if not parts:
            raise RadioMapInputError("no radio-map statistics to add")
        acc = cls(
            parts[0].cell_size_m,
            np.concatenate([p.cell_key for p in parts]),
            np.concatenate([p.cell_scans for p in parts]),
            np.concatenate([p.cell_sum_xy_m for p in parts]),
            np.concatenate([p.entry_key for p in parts]),
            np.concatenate([p.entry_count for p in parts]),
            np.concatenate([p.entry_sum_dbm for p in parts]),
            np.concatenate([p.entry_sum2_dbm2 for p in parts]),
            {},
        )
        if any(p.cell_size_m != acc.cell_size_m for p in parts):
            raise RadioMapInputError("cannot add radio-map statistics of different cell sizes")
        out = acc._combine(cls.empty(acc.cell_size_m), +1)
        out.scans = {k: sum(p.scans.get(k, 0) for p in parts) for k in set().union(*(p.scans for p in parts))}
        return out

    def _combine(self, other: "WalkStats", sign: int) -> "WalkStats":
        if other.cell_size_m != self.cell_size_m:
            raise RadioMapInputError(
                f"cannot combine radio-map statistics of cell "
                f"{self.cell_size_m:g} m and {other.cell_size_m:g} m"
            )
        ck, cv = _group_sum(
            np.concatenate([self.cell_key, other.cell_key]),
            np.concatenate(
                [
                    np.column_stack([self.cell_scans, self.cell_sum_xy_m]),
                    sign * np.column_stack([other.cell_scans, other.cell_sum_xy_m]),
                ]
            ),
        )
        ek, ev = _group_sum(
            np.concatenate([self.entry_key, other.entry_key]),
            np.concatenate(
                [
                    np.column_stack([self.entry_count, self.entry_sum_dbm, self.entry_sum2_dbm2]),
                    sign * np.column_stack([other.entry_count, other.entry_sum_dbm, other.entry_sum2_dbm2]),
                ]
            ),
        )
        c_n, e_n = np.rint(cv[:, 0]).astype(np.int64), np.rint(ev[:, 0]).astype(np.int64)
        if (c_n < 0).any() or (e_n < 0).any():
            raise RadioMapInputError("radio-map statistics: subtracted more than the total holds")
        c_keep, e_keep = c_n > 0, e_n > 0
        scans = {
            k: self.scans.get(k, 0) + sign * other.scans.get(k, 0) for k in set(self.scans) | set(other.scans)
        }
        return WalkStats(
            self.cell_size_m,
            ck[c_keep],
            c_n[c_keep],
            cv[c_keep, 1:],
            ek[e_keep],
            e_n[e_keep],
            ev[e_keep, 1],
            ev[e_keep, 2],
            scans,
        )

    def __add__(self, other: "WalkStats") -> "WalkStats":
        return self._combine(other, +1)

    def __sub__(self, other: "WalkStats") -> "WalkStats":
        """``self`` without ``other``, which must be part of it (e.g. total − one walk)."""
        return self._combine(other, -1)

    def to_site(
        self,
        min_count: int = DEFAULT_MIN_COUNT,
        name: str = "",
        map_rotation_deg: float = 0.0,
        floor_height_m: float = DEFAULT_FLOOR_HEIGHT_M,
        floor_heights_m=None,
        lowest_floor: int | None = None,
        origin_deg: tuple[float, float] | None = None,
        source: str = "",
    ) -> tuple[site_t, dict]:
        """The walk-mode site of these statistics, as :func:`build_site` would build it from the
        same recordings; returns (site, summary)."""
        if min_count < 1:
            raise RadioMapInputError(f"min count {min_count} must be >= 1")
        if len(self.cell_key) == 0:
            raise RadioMapInputError("no scan could be placed on the truth (empty statistics)")
        n = self.cell_scans
        rp_x, rp_y = self.cell_sum_xy_m[:, 0] / n, self.cell_sum_xy_m[:, 1] / n
        rp_floor = self.cell_key[:, 0].copy()
        # entry -> RP index: entry keys are sorted by (floor, iy, ix, bssid), cells by (f, iy, ix)
        cell_code = _row_codes(self.cell_key)
        rp = np.searchsorted(cell_code, _row_codes(self.entry_key[:, :3]))
        keys = np.column_stack([self.entry_key[:, 3], rp])
        order = np.lexsort((keys[:, 1], keys[:, 0]))
        keys = keys[order]
        count = self.entry_count[order]
        mean = self.entry_sum_dbm[order] / count
        var = np.maximum(self.entry_sum2_dbm2[order] / count - mean**2, 0.0)
        site, kept, has_entry = _assemble_site(
            keys,
            count,
            mean,
            np.sqrt(var),
            rp_x,
            rp_y,
            rp_floor,
            n.copy(),
            min_count=min_count,
            source=source
            or f"stridefix {TOOL_VERSION}: walk mode from sufficient statistics; "
            f"cell {self.cell_size_m:g} m; min count {min_count}",
            name=name,
            map_rotation_deg=map_rotation_deg,
            cell_size_m=self.cell_size_m,
            floor_height_m=floor_height_m,
            floor_heights_m=floor_heights_m,
            lowest_floor=lowest_floor,
            origin_deg=origin_deg,
        )
        summary = site_summary(site)
        summary.update(
            mode="walk",
            mode_reason="sufficient statistics",
            scans=dict(self.scans),
            entries_below_min_count=int(np.sum(~kept)),
            min_count=min_count,
            rps_dropped_no_entry=int(np.sum(~has_entry)),
        )
        return site, summary


def _row_codes(rows: np.ndarray) -> np.ndarray:
    """A sortable code per (floor, iy, ix) row, order-preserving (lexicographic)."""
    r = rows.astype(np.int64)
    return ((r[:, 0] + (1 << 15)) << 42) + ((r[:, 1] + (1 << 20)) << 21) + (r[:, 2] + (1 << 20))


# --- summaries and plots -------------------------------------------------------------------------


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
        info = {
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
    }


def format_summary(s: dict) -> str:
    """Human-readable lines of a build or site summary."""
    lines = []
    if s.get("name"):
        lines.append(f"site        {s['name']}")
    if "mode" in s:
        lines.append(f"mode        {s['mode']} ({s['mode_reason']})")
        sc = s["scans"]
        skipped = ", ".join(f"{k[8:]} {v}" for k, v in sc.items() if k.startswith("skipped_") and v)
        lines.append(
            f"scans       {sc['used']} used of {sc['total']} in "
            f"{len(s['recordings'])} recording(s)" + (f"; skipped: {skipped}" if skipped else "")
        )
    else:
        lines.append(f"source      {s['source']}")
    lines.append(
        f"radio map   {s['n_rp']} RPs, {s['n_ap']} APs, {s['n_entries']} entries"
        + (
            f" ({s['entries_below_min_count']} below min count {s['min_count']} dropped"
            f", and {s['rps_dropped_no_entry']} RPs left without one)"
            if "min_count" in s
            else ""
        )
        + (f"; {s['rps_without_ap']} RP(s) with no AP" if s["rps_without_ap"] else "")
    )
    cell = f"cell {s['cell_size_m']:g} m" if s["cell_size_m"] > 0 else "surveyed points"
    geo = f", origin {s['geo'][0]:.6f}, {s['geo'][1]:.6f}" if s.get("geo") else ""
    lines.append(f"frame       rotation {s['map_rotation_deg']:g} deg, {cell}{geo}")
    lines.append(f"floors      {s['n_floors']} from {s['lowest_floor']}")
    for f, info in s["floors"].items():
        text = f"  floor {f:>3}  h {info['height_m']:6.2f} m  {info['rps']:5d} RPs  {info['aps']:4d} APs"
        if info["rps"]:
            text += (
                f"  x {info['x_range_m'][0]:.1f}..{info['x_range_m'][1]:.1f} m"
                f"  y {info['y_range_m'][0]:.1f}..{info['y_range_m'][1]:.1f} m"
                f"  {info['mean_aps_per_rp']:.1f} APs/RP  {info['mean_scans_per_rp']:.1f} scans/RP"
            )
            if "cell_area_m2" in info:
                text += f"  {info['cell_area_m2']:.0f} m² covered"
        lines.append(text)
    return "\n".join(lines)


def plot_site(site: site_t, png_path: str) -> None:
    """PNG of the RPs per floor (one panel each), coloured by the number of APs heard."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rp_floor = np.asarray(site.rp_floor)
    n_aps = np.bincount(np.asarray(site.entry_rp, dtype=np.int64), minlength=site.n_rp)
    floors = [
        site.lowest_floor + i for i in range(site.n_floors) if np.any(rp_floor == site.lowest_floor + i)
    ] or [site.lowest_floor]
    fig, axes = plt.subplots(
        1, len(floors), figsize=(5 * len(floors), 4.5), squeeze=False, constrained_layout=True
    )
    vmax = max(1, int(n_aps.max())) if site.n_rp else 1
    for ax, f in zip(axes[0], floors):
        sel = rp_floor == f
        sc = ax.scatter(
            np.asarray(site.rp_x_m)[sel],
            np.asarray(site.rp_y_m)[sel],
            c=n_aps[sel],
            cmap="viridis",
            vmin=0,
            vmax=vmax,
            s=18,
        )
        ax.set_title(f"floor {f}: {int(sel.sum())} RPs")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    fig.colorbar(sc, ax=list(axes[0]), label="APs heard at RP")
    fig.suptitle(site.name or "radio map")
    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    fig.savefig(png_path, dpi=110)
    plt.close(fig)


# --- command line --------------------------------------------------------------------------------


def _float_list(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of numbers") from None


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare ``radiomap build`` and ``radiomap show``."""
    p = subparsers.add_parser(
        "radiomap",
        help="build a site file (radio map) from logs; show one",
        description="Radio maps: build a site file from Wi-Fi scans with "
        "ground truth, or summarise/plot a site file.",
    )
    sub = p.add_subparsers(dest="radiomap_command", metavar="ACTION", required=True)
    b = sub.add_parser(
        "build",
        help="site file from LCM logs with WIFI + TRUTH",
        description="Build a site file from LCM logs with WIFI and TRUTH. An argument 'a,b' is "
        "one recording of both files; an argument holding WIFI and TRUTH is a "
        "recording; the other arguments (e.g. firmware log + truth log) are merged "
        "into one recording.",
    )
    b.add_argument("logs", nargs="+", metavar="LOG")
    b.add_argument("--out", required=True, metavar="SITE.sfsite", help="site file to write")
    b.add_argument(
        "--mode",
        choices=MODES,
        default="auto",
        help="survey: one RP per surveyed point; walk: RPs on a grid; auto: survey "
        "when the truth is static during most scans, repeated per spot (default)",
    )
    b.add_argument(
        "--cell-size-m",
        type=float,
        default=DEFAULT_CELL_SIZE_M,
        help=f"grid cell of walk mode [m] (default {DEFAULT_CELL_SIZE_M:g})",
    )
    b.add_argument("--name", default="", help="site name (default: the output file's stem)")
    b.add_argument(
        "--map-rotation-deg",
        type=float,
        default=0.0,
        help="map frame = magnetic east-north turned CCW by this angle [deg]",
    )
    g = b.add_mutually_exclusive_group()
    g.add_argument(
        "--floor-height-m",
        type=float,
        default=DEFAULT_FLOOR_HEIGHT_M,
        help=f"storey height: floor f at f × this [m] (default {DEFAULT_FLOOR_HEIGHT_M:g})",
    )
    g.add_argument(
        "--floor-heights-m",
        type=_float_list,
        default=None,
        metavar="H0,H1,...",
        help="walking-surface height of each floor from the lowest [m]",
    )
    b.add_argument(
        "--lowest-floor",
        type=int,
        default=None,
        help="lowest floor index (default: the lowest with reference points)",
    )
    b.add_argument(
        "--min-count",
        type=int,
        default=DEFAULT_MIN_COUNT,
        help=f"drop (RP, AP) entries heard in fewer scans (default {DEFAULT_MIN_COUNT})",
    )
    b.add_argument(
        "--origin-deg",
        type=_float_list,
        default=None,
        metavar="LAT,LON",
        help="geo-reference of the map origin (sets has_geo)",
    )
    b.add_argument(
        "--scan-duration-ms",
        type=float,
        default=DEFAULT_SCAN_DURATION_MS,
        help="truth must stay put this long after a scan's start for it to count as "
        "static [ms] (default 0: the samples around the start)",
    )
    b.add_argument(
        "--static-tol-m",
        type=float,
        default=DEFAULT_STATIC_TOL_M,
        help=f"truth within this distance counts as the same spot [m] (default {DEFAULT_STATIC_TOL_M:g})",
    )
    s = sub.add_parser(
        "show",
        help="summary (and PNG) of a site file",
        description="Check a site file and print its summary; --png plots the "
        "reference points per floor coloured by APs heard.",
    )
    s.add_argument("site", metavar="SITE.sfsite")
    s.add_argument("--png", default=None, metavar="PATH", help="write a PNG of the RPs")
    return p


def run_build(args: argparse.Namespace) -> tuple[site_t, dict]:
    """Build and write the site of ``args`` (the ``build`` options); return (site, summary)."""
    if args.origin_deg is not None and len(args.origin_deg) != 2:
        raise RadioMapInputError("--origin-deg needs LAT,LON")
    recordings = load_recordings(args.logs)
    name = args.name or os.path.splitext(os.path.basename(args.out))[0]
    site, summary = build_site(
        recordings,
        mode=args.mode,
        cell_size_m=args.cell_size_m,
        min_count=args.min_count,
        name=name,
        map_rotation_deg=args.map_rotation_deg,
        floor_height_m=args.floor_height_m,
        floor_heights_m=args.floor_heights_m,
        lowest_floor=args.lowest_floor,
        origin_deg=tuple(args.origin_deg) if args.origin_deg else None,
        scan_duration_ms=args.scan_duration_ms,
        static_tol_m=args.static_tol_m,
    )
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    summary["bytes"] = write_site(args.out, site)
    return site, summary


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix radiomap``; returns the exit status."""
    prog = f"stridefix radiomap {args.radiomap_command}"
    try:
        if args.radiomap_command == "build":
            _, summary = run_build(args)
            print(format_summary(summary))
            print(f"wrote {args.out} ({summary['bytes']} bytes)")
        else:
            site = read_site(args.site)
            print(format_summary(site_summary(site)))
            if args.png:
                plot_site(site, args.png)
                print(f"wrote {args.png}")
    except (LogReadError, RadioMapInputError, SiteFileError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    return 0
