"""BLE beacons of a site from walks with truth: the site's log-distance path-loss model and, for sites
without a beacon table (msindoor), each beacon's position.

Model: RSSI(d) = A − 10·n·log10(max(d, :data:`MIN_RANGE_M`)) + ε, ε ~ N(0, σ²), d the horizontal
distance from the walker (the truth, linearly interpolated in time between waypoints on one floor)
to the beacon. A reading outside the truth's span, or between waypoints on different floors, is not
placed.

* :func:`fit_model` — known beacon positions (a table): A and n by least squares over every placed
  reading on the beacon's floor, σ = the residuals' standard deviation.
* :func:`learn_beacons` — unknown positions: alternating least squares. Start with n = 2 (free space)
  and A = the 95th-percentile RSSI; per beacon, its position minimises the squared RSSI residuals
  (every beacon at once by :func:`~.beacon_solve.solve_positions`, a batched bounded
  Levenberg–Marquardt, started at the RSSI-weighted centroid of its strongest readings, bounded to
  the box of its readings ± :data:`POSITION_MARGIN_M`); then A and n by linear least squares over all
  beacons; repeated :data:`ALTERNATIONS` times. A beacon needs :data:`MIN_READINGS` placed readings
  from :data:`MIN_CELLS` distinct 2 m cells on one floor (else the position is not determined, and
  it is left out); a beacon whose fit leaves an RMS residual above :data:`MAX_RMS_FACTOR` × the
  site's σ is left out too (a moved beacon, or one heard through floors), and so is one whose fit ends
  within :data:`EDGE_M` of its box or whose position's 1σ (from the fit's information matrix) exceeds
  :data:`MAX_POSITION_SIGMA_M` (the readings did not place it well enough for its fixes).

Cost: O(R) per solver iteration for R readings (numpy passes over all beacons' readings at once),
a few tens of iterations per alternation; O(R log R) once to group the readings by beacon.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

#: Readings closer than MIN_RANGE_M [m] are taken at that range (the model's reference distance, 1 m).
from stridefix_analyzer.radiomap.beacon_solve import MIN_RANGE_M, solve_positions

#: Fewest placed readings and distinct 2 m cells that determine a beacon's position (3 unknowns:
#: x, y and the residual scale need well over 3 independent positions).
MIN_READINGS = 15
MIN_CELLS = 6
CELL_M = 2.0
#: Largest 1σ of a learnt beacon position kept [m]: the firmware takes a beacon as known to
#: ble.position_sigma_m (3 m); a beacon placed worse than that would make its BLE fixes claim too much.
MAX_POSITION_SIGMA_M = 3.0
#: A learnt position within this of its box's edge [m] is one the readings did not determine.
EDGE_M = 0.5
#: A learnt position stays within the box of its readings ± this [m] (a beacon is heard from ~20 m).
POSITION_MARGIN_M = 10.0
ALTERNATIONS = 5
MAX_RMS_FACTOR = 2.0
#: Defaults of the site model where nothing can be learnt: −59 dBm at 1 m (the iBeacon "measured
#: power" convention), n = 2 (free space), σ = 6 dB (indoor shadowing, a typical 4–8 dB).
DEFAULT_MODEL = {"rssi_1m_dbm": -59.0, "path_loss_exponent": 2.0, "range_sigma_db": 6.0}


def place_readings(recordings: Sequence[Any]) -> dict[str, np.ndarray]:
    """Every BLE reading of the recordings placed on its recording's truth: columns beacon_id, x_m,
    y_m, floor, rssi_dbm (readings that cannot be placed are dropped; ``n_total`` counts all)."""
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("beacon_id", "x_m", "y_m", "floor", "rssi_dbm")}
    n_total = 0
    for rec in recordings:
        ble, truth = rec.ble, rec.truth
        n_total += len(ble)
        if not len(ble) or len(truth) < 2:
            continue
        t, tt = ble["t_us"].astype(np.float64), truth["t_us"].astype(np.float64)
        i = np.searchsorted(tt, t, side="right")
        ok = (i >= 1) & (i < len(tt))
        i = np.clip(i, 1, len(tt) - 1)
        f0, f1 = truth["floor"][i - 1], truth["floor"][i]
        ok &= f0 == f1
        w = np.where(tt[i] > tt[i - 1], (t - tt[i - 1]) / np.maximum(tt[i] - tt[i - 1], 1.0), 0.0)
        x = truth["x_m"][i - 1] + w * (truth["x_m"][i] - truth["x_m"][i - 1])
        y = truth["y_m"][i - 1] + w * (truth["y_m"][i] - truth["y_m"][i - 1])
        for k, v in (("beacon_id", ble["beacon_id"]), ("x_m", x), ("y_m", y), ("floor", f0)):
            cols[k].append(np.asarray(v)[ok])
        cols["rssi_dbm"].append(ble["rssi_dbm"][ok])
    out = {k: np.concatenate(v) if v else np.zeros(0) for k, v in cols.items()}
    out["beacon_id"] = out["beacon_id"].astype(np.int64)
    out["floor"] = out["floor"].astype(np.int64)
    out["n_total"] = np.asarray(n_total)
    return out


def _log_d(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    return np.log10(np.maximum(np.hypot(dx, dy), MIN_RANGE_M))


def _linear_model(rssi: np.ndarray, logd: np.ndarray) -> tuple[float, float]:
    """(A, n) of rssi ≈ A − 10·n·logd by least squares (n from the data only when logd varies)."""
    design = np.column_stack([np.ones_like(logd), -10.0 * logd])
    (a, n), *_ = np.linalg.lstsq(design, rssi, rcond=None)
    return float(a), float(n)


def fit_model(placed: dict[str, np.ndarray], table: dict[int, tuple[float, float, int]]) -> dict[str, Any]:
    """The site model from readings of beacons at known positions ``table`` (id → x, y, floor)."""
    keep = np.array(
        [
            b in table and table[b][2] == f
            for b, f in zip(placed["beacon_id"].tolist(), placed["floor"].tolist())
        ],
        dtype=bool,
    )
    if keep.sum() < MIN_READINGS:
        return {**DEFAULT_MODEL, "readings": int(keep.sum()), "learnt": False}
    ids = placed["beacon_id"][keep]
    bx = np.array([table[b][0] for b in ids.tolist()])
    by = np.array([table[b][1] for b in ids.tolist()])
    logd = _log_d(placed["x_m"][keep] - bx, placed["y_m"][keep] - by)
    rssi = placed["rssi_dbm"][keep]
    a, n = _linear_model(rssi, logd)
    resid = rssi - (a - 10.0 * n * logd)
    return {
        "rssi_1m_dbm": a,
        "path_loss_exponent": n,
        "range_sigma_db": float(np.std(resid)),
        "readings": int(keep.sum()),
        "learnt": n > 0,
    }


def _groups(placed: dict[str, np.ndarray]) -> tuple[dict[int, np.ndarray], dict[int, str]]:
    """Per beacon the rows (ascending) of the floor it is heard most on, for the beacons with
    :data:`MIN_READINGS` readings in :data:`MIN_CELLS` cells there; the rest with the reason."""
    ids, floors = placed["beacon_id"], placed["floor"]
    order = np.argsort(ids, kind="stable")  # rows ascending within each beacon
    uniq, first = np.unique(ids[order], return_index=True)
    cx = np.floor_divide(placed["x_m"], CELL_M).astype(np.int64)
    cy = np.floor_divide(placed["y_m"], CELL_M).astype(np.int64)
    groups: dict[int, np.ndarray] = {}
    left_out: dict[int, str] = {}
    for b, rows in zip(uniq.tolist(), np.split(order, first[1:])):
        fl, counts = np.unique(floors[rows], return_counts=True)
        rows = rows[floors[rows] == fl[np.argmax(counts)]]  # the floor it is heard most on
        cells = len(np.unique(cx[rows] + 1j * cy[rows])) if len(rows) else 0
        if len(rows) < MIN_READINGS or cells < MIN_CELLS:
            left_out[b] = f"{len(rows)} readings in {cells} cells"
            continue
        groups[b] = rows
    return groups, left_out


def learn_beacons(placed: dict[str, np.ndarray]) -> dict[str, Any]:
    """Beacon positions and the site model from placed readings (see the module docstring).

    Returns ``beacons`` {id: (x, y, floor, n_readings, rms_db)}, the model (``rssi_1m_dbm``,
    ``path_loss_exponent``, ``range_sigma_db``, ``learnt``) and ``left_out`` {id: reason}."""
    groups, left_out = _groups(placed)
    rssi_all, floors = placed["rssi_dbm"], placed["floor"]
    a = float(np.percentile(rssi_all, 95)) if len(rssi_all) else DEFAULT_MODEL["rssi_1m_dbm"]
    n = DEFAULT_MODEL["path_loss_exponent"]
    if not groups:
        return {"beacons": {}, **DEFAULT_MODEL, "learnt": False, "left_out": left_out, "readings": 0}
    start = np.zeros((len(groups), 2))
    for k, rows in enumerate(groups.values()):
        x, y, r = placed["x_m"][rows], placed["y_m"][rows], rssi_all[rows]
        top = r >= np.percentile(r, 75)
        w = 10.0 ** (r[top] / 10.0)
        start[k] = (np.sum(w * x[top]) / w.sum(), np.sum(w * y[top]) / w.sum())
    rows_all = np.concatenate(list(groups.values()))
    g = np.repeat(np.arange(len(groups)), [len(rows) for rows in groups.values()])
    qx, qy, r_all = placed["x_m"][rows_all], placed["y_m"][rows_all], rssi_all[rows_all]
    lo = np.column_stack([np.minimum.reduceat(qx, _starts(g)), np.minimum.reduceat(qy, _starts(g))])
    hi = np.column_stack([np.maximum.reduceat(qx, _starts(g)), np.maximum.reduceat(qy, _starts(g))])
    lo, hi = lo - POSITION_MARGIN_M, hi + POSITION_MARGIN_M
    pos = start
    for _ in range(ALTERNATIONS):
        pos = solve_positions(g, qx, qy, r_all, a, n, np.clip(pos, lo + 1e-6, hi - 1e-6), lo, hi)
        logd = _log_d(qx - pos[g, 0], qy - pos[g, 1])
        a, n = _linear_model(r_all, logd)
        if not n > 0:
            a, n = _linear_model(r_all + 10.0 * DEFAULT_MODEL["path_loss_exponent"] * logd, 0 * logd)
            n = DEFAULT_MODEL["path_loss_exponent"]
    resid = r_all - (a - 10.0 * n * logd)
    sigma = float(np.std(resid))
    rms_g = np.sqrt(np.bincount(g, resid * resid) / np.bincount(g))
    pos_sigma = _position_sigma(g, qx - pos[g, 0], qy - pos[g, 1], n, sigma, len(groups))
    beacons: dict[int, tuple[float, float, int, int, float]] = {}
    for k, (b, rows) in enumerate(groups.items()):
        rms = float(rms_g[k])
        if np.any(pos[k] <= lo[k] + EDGE_M) or np.any(pos[k] >= hi[k] - EDGE_M):
            # the fit ran to the edge of the box it may lie in: the readings do not place it (a beacon
            # heard only from one side, or only weakly); on 5 walks of site1/F2 such beacons were
            # tens of metres off and their fixes started the schemes 40 m away
            left_out[b] = f"fit at the edge of its box (readings ± {POSITION_MARGIN_M:g} m): not placed"
            continue
        if not pos_sigma[k] <= MAX_POSITION_SIGMA_M:
            left_out[b] = (
                f"position known to {pos_sigma[k]:.1f} m (1 sigma) > {MAX_POSITION_SIGMA_M:g} m: its fixes would "
                "mislead"
            )
            continue
        if rms > MAX_RMS_FACTOR * sigma:
            left_out[b] = f"RMS residual {rms:.1f} dB > {MAX_RMS_FACTOR:g} x site sigma {sigma:.1f} dB"
            continue
        beacons[b] = (float(pos[k, 0]), float(pos[k, 1]), int(floors[rows[0]]), len(rows), rms)
    kept = np.isin(g, [k for k, b in enumerate(groups) if b in beacons])
    if kept.any():
        sigma = float(np.std(resid[kept]))
    return {
        "beacons": beacons,
        "rssi_1m_dbm": a,
        "path_loss_exponent": n,
        "range_sigma_db": sigma,
        "learnt": True,
        "left_out": left_out,
        "readings": int(kept.sum()),
    }


def _position_sigma(
    g: np.ndarray, dx: np.ndarray, dy: np.ndarray, n: float, sigma_db: float, n_groups: int
) -> np.ndarray:
    """Per beacon, √(½ trace) of its position's covariance from the fit (the inverse of Σ JᵀJ/σ² over
    its readings, J = ∂RSSI/∂position = 10·n/ln 10 · (p − q)/d²; readings nearer than MIN_RANGE_M
    carry no gradient); +∞ where the readings do not determine it (a singular information matrix)."""
    d2 = np.maximum(dx * dx + dy * dy, MIN_RANGE_M**2)
    k = 10.0 * n / np.log(10.0) / max(sigma_db, 1e-6)
    jx, jy = k * -dx / d2, k * -dy / d2  # the model's slope in the beacon's x, y (p − q = −(q − p))
    ixx = np.bincount(g, jx * jx, n_groups)
    ixy = np.bincount(g, jx * jy, n_groups)
    iyy = np.bincount(g, jy * jy, n_groups)
    det = ixx * iyy - ixy * ixy
    with np.errstate(divide="ignore", invalid="ignore"):
        var = np.where(det > 0.0, 0.5 * (ixx + iyy) / det, np.inf)
    return np.sqrt(var)


def _starts(g: np.ndarray) -> np.ndarray:
    """Where each run of equal values of the sorted group index ``g`` starts."""
    return np.flatnonzero(np.r_[True, g[1:] != g[:-1]])


def mac_check(
    placed: dict[str, np.ndarray], table: dict[str, tuple[float, float, int]], radius_m: float = 5.0
) -> dict[str, Any]:
    """Which MAC is loudest near each table position: per (name, MAC) the median RSSI of the readings
    within ``radius_m`` of the position on its floor. Returns {name: {"loudest": id, "median_dbm":
    {id: dBm}, "readings": n}}."""
    out: dict[str, Any] = {}
    for name, (tx, ty, tf) in table.items():
        near = (np.hypot(placed["x_m"] - tx, placed["y_m"] - ty) <= radius_m) & (placed["floor"] == tf)
        med = {
            int(b): float(np.median(placed["rssi_dbm"][near & (placed["beacon_id"] == b)]))
            for b in np.unique(placed["beacon_id"][near]).tolist()
        }
        loudest = max(med, key=lambda b: med[b]) if med else None
        out[name] = {"loudest": loudest, "median_dbm": med, "readings": int(near.sum())}
    return out


def site_fields(beacons: dict[int, tuple[float, float, int]], model: dict[str, Any]) -> dict[str, Any]:
    """site_t fields of beacons {id: (x, y, floor, ...)} and a model (ids ascending, own RSSI NaN)."""
    ids = sorted(beacons)
    return {
        "beacon_id": ids,
        "beacon_x_m": [beacons[b][0] for b in ids],
        "beacon_y_m": [beacons[b][1] for b in ids],
        "beacon_floor": [int(beacons[b][2]) for b in ids],
        "beacon_rssi_1m_dbm": [math.nan] * len(ids),
        "ble_rssi_1m_dbm": float(model["rssi_1m_dbm"]),
        "ble_path_loss_exponent": float(model["path_loss_exponent"]),
        "ble_range_sigma_db": float(model["range_sigma_db"]),
    }


#: A table position is matched to the MAC loudest near it (mac_check) when it has this many readings
#: within the check radius and leads the runner-up by this margin [dB] (else no MAC is assumed).
MATCH_MIN_READINGS = 10
MATCH_MARGIN_DB = 6.0


def site_beacons(
    recordings: Sequence[Any], table: dict[str, tuple[float, float, int]] | None
) -> dict[str, Any]:
    """The beacons and model a build writes: with a ``table`` (name → x, y, floor in the map frame),
    each name matched to a MAC by :func:`mac_check` (decisive matches only) at the table's position,
    the model fitted on those; the MACs left are learnt (:func:`learn_beacons`) like a site without a
    table. Returns ``fields`` (site_t fields, empty without readings) and the ``report``."""
    return placed_beacons(place_readings(recordings), table)


def merge_placed(parts: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """The placed readings of several :func:`place_readings` results as one (realbench's folds add
    the training walks' readings)."""
    keys = ("beacon_id", "x_m", "y_m", "floor", "rssi_dbm")
    out = {k: np.concatenate([p[k] for p in parts]) if parts else np.zeros(0) for k in keys}
    out["beacon_id"] = out["beacon_id"].astype(np.int64)
    out["floor"] = out["floor"].astype(np.int64)
    out["n_total"] = np.asarray(sum(int(p["n_total"]) for p in parts))
    return out


def placed_beacons(
    placed: dict[str, np.ndarray], table: dict[str, tuple[float, float, int]] | None
) -> dict[str, Any]:
    """:func:`site_beacons` of readings already placed (:func:`place_readings`)."""
    report: dict[str, Any] = {"readings": int(placed["n_total"]), "placed": len(placed["rssi_dbm"])}
    if not len(placed["rssi_dbm"]):
        return {"fields": {}, "report": report}
    known: dict[int, tuple[float, float, int]] = {}
    if table:
        check = mac_check(placed, table)
        matches: dict[str, str | None] = {}
        for name, c in check.items():
            med = sorted(c["median_dbm"].values(), reverse=True)
            decisive = c["loudest"] is not None and c["readings"] >= MATCH_MIN_READINGS
            decisive = decisive and (len(med) < 2 or med[0] - med[1] >= MATCH_MARGIN_DB)
            if decisive and c["loudest"] not in known:
                known[c["loudest"]] = table[name]
                matches[name] = f"{c['loudest']:012x}"
            else:
                matches[name] = None
        report["mac_check"] = {
            n: {
                "loudest": None if c["loudest"] is None else f"{c['loudest']:012x}",
                "readings": c["readings"],
                "median_dbm": {f"{k:012x}": round(v, 1) for k, v in c["median_dbm"].items()},
            }
            for n, c in check.items()
        }
        report["table_matched"] = matches
    rest = ~np.isin(placed["beacon_id"], list(known))
    learnt = learn_beacons({k: (v[rest] if v.ndim else v) for k, v in placed.items()})
    model = fit_model(placed, known) if known else {}
    if not model.get("learnt"):
        model = learnt if learnt["learnt"] else {**DEFAULT_MODEL, "learnt": False}
    beacons: dict[int, tuple[float, float, int]] = dict(known)
    beacons.update({b: v[:3] for b, v in learnt["beacons"].items()})
    report.update(
        from_table=len(known),
        learnt=len(learnt["beacons"]),
        left_out=len(learnt["left_out"]),
        model={k: model[k] for k in ("rssi_1m_dbm", "path_loss_exponent", "range_sigma_db")},
        model_learnt=bool(model.get("learnt")),
        learnt_rms_db=[round(v[4], 2) for v in learnt["beacons"].values()],
    )
    return {"fields": site_fields(beacons, model) if beacons else {}, "report": report}
