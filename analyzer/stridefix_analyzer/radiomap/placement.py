"""Placing Wi-Fi scans on the truth: position, floor and static flag of every scan of a recording.

Placing a scan (time ``t`` = scan start [µs], the position the simulator measures at): truth is
interpolated linearly in time between the samples around ``t`` (sparse waypoints work); a scan outside
the truth's time span, or between two samples on different floors, is skipped and counted. A scan is
*static* when every truth sample from the last one at or before ``t`` to the first one at or after
``t + scan_duration`` is within ``static_tol_m`` of the first and on the same floor.

A BSSID heard twice in one scan counts once, at its strongest RSSI (:func:`ap_rows`).
"""

from __future__ import annotations

import numpy as np

from stridefix_analyzer.radiomap.recordings import Recording

DEFAULT_STATIC_TOL_M = 0.05
DEFAULT_SCAN_DURATION_MS = 0

_BSSID_LIMIT = 1 << 48

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


def collect_scans(recordings: list[Recording], scan_duration_ms: float, static_tol_m: float) -> dict:
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
        xs.append(p["x_m"])
        ys.append(p["y_m"])
        fs.append(p["floor"])
        st.append(p["static"])
        scan_ok.append(p["skip"] == 0)
        recs.append(np.full(len(rec.wifi), r, dtype=np.int64))
        ap_scan.append(rec.wifi_ap["scan_row"] + base)
        ap_bssid.append(rec.wifi_ap["bssid"])
        ap_rssi.append(rec.wifi_ap["rssi_dbm"])
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


def ap_rows(placed: dict, scan_used: np.ndarray):
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
