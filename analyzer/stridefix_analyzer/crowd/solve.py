"""The weighted coordinate solver of Kannan (2024) over the points of several walks.

Points: per walk, its Wi-Fi scans; with waypoint truth (real walks) also the waypoints, merged in time
order. A waypoint point borrows the fingerprint of the walk's nearest scan within ``borrow_s``.
*Truth points* are the scan points (dense, simulated truth) or the waypoint points (real walks).

Unknowns: p_k = (x_k, y_k) [m] for every point. Rows (Eqs. 7–10, 18–19 of the thesis):

* anchor rows p_a − q_a (2 per anchor, weight 1) at a subset of the truth points: ``every:K`` = the
  walk's truth points 0, K, 2K, … (thesis: every 4th); ``every-other-waypoint`` = ``every:2``;
* range rows w·(b − ‖p_i − p_j‖), b [m] from
  - PDR: the PDR distance between points i < j of one walk with j − i ≤ ``pdr_span``
    (1 = consecutive points; 0 = every pair of the walk), see :mod:`.crowd_walks`;
  - Wi-Fi: the model distance g(d) of two points' fingerprints (any walks, same floor);
* weights w = 1/(m·b + c) (thesis optimum m = 1, c = 2), or 1 without weights.

Range sets (``ranges``): ``pdr``; ``wifi``; ``hybrid`` = PDR rows kept only when the pair passes the
Wi-Fi reliability filter (the thesis's PDR + Wi-Fi: "PDR is the base, Wi-Fi filters it"; a pair
whose points lack a fingerprint is kept, a pair with no common AP dropped); ``both`` = PDR rows plus
the Wi-Fi rows that pass the filter. The filter keeps g(d) ≤ τ·max g over all candidate Wi-Fi pairs
(τ = 0.45), ``tau=None`` = no filter.

Solver: ``stridefix_native.solve_coordinates`` (C++/Ceres) when importable, else the scipy reference
here (``least_squares``, trust-region reflective, sparse analytic Jacobian, LSMR). The native call
used: ``solve_coordinates(n, anchors_idx (a,), anchors_xy (a,2), pairs (k,2), ranges_m (k,), weights
(k,), init_xy=x0, max_iterations)`` → dict with ``xy``; with ``solver="auto"`` any failure falls back
to scipy and the reason is reported. Initial guess: per walk, the anchors
interpolated linearly in time (held before the first / after the last).

Error: ‖p̂ − truth‖ at the non-anchor truth points: mean, std (ddof 1, the thesis's MATLAB std),
median, p90, RMSE; the thesis also averaged over the anchors (reported as ``mean_all_m``).
"""

from __future__ import annotations

import dataclasses
import math
import re
import time
from typing import Protocol

import numpy as np
import scipy.sparse as sp
from scipy.optimize import least_squares

from stridefix_analyzer.crowd.model import DEFAULT_TAU, DistanceModel, _block, _Prepared
from stridefix_analyzer.crowd.walks import DEFAULT_BORROW_S, CrowdInputError, ScanSet, Walk

RANGES = ("pdr", "wifi", "both", "hybrid")
DEFAULT_WEIGHTS = (1.0, 2.0)
SOLVERS = ("auto", "native", "scipy")
DEFAULT_MAX_NFEV = 8000  # thesis: lsqnonlin MaxFunctionEvaluations


def parse_anchors(spec: str) -> int:
    """Anchor spacing K of ``every:K`` / ``every-other-waypoint`` (= 2)."""
    if spec == "every-other-waypoint":
        return 2
    m = re.fullmatch(r"every:(\d+)", spec or "")
    if not m or int(m.group(1)) < 1:
        raise CrowdInputError(f"--anchors {spec!r}: expected every:K (K ≥ 1) or every-other-waypoint")
    return int(m.group(1))


@dataclasses.dataclass
class Points:
    """The unknown points of a set of walks, (n,) each; ``fp`` row of the scan set or −1."""

    walk: np.ndarray
    t_us: np.ndarray
    is_scan: np.ndarray
    fp: np.ndarray
    truth_xy_m: np.ndarray
    floor: np.ndarray
    is_truth: np.ndarray
    dr_xy_m: np.ndarray
    dr_path_m: np.ndarray


def make_points(walks: list[Walk], scans: ScanSet, borrow_s: float = DEFAULT_BORROW_S) -> Points:
    """Points of every walk (module docstring), in walk then time order."""
    parts = []
    for k, w in enumerate(walks):
        sidx = np.flatnonzero((scans.walk == k) & scans.usable)
        st = scans.t_us[sidx]
        if w.dense_truth:
            t, is_scan, fp = st, np.ones(len(st), bool), sidx
        else:
            wt = w.truth_t_us
            near = np.full(len(wt), -1, np.int64)
            if len(st):
                j = (
                    np.clip(np.searchsorted(st, wt), 1, len(st))
                    if len(st) > 1
                    else np.zeros(len(wt), np.int64)
                )
                cand = np.stack([np.clip(j - 1, 0, len(st) - 1), np.clip(j, 0, len(st) - 1)])
                dt = np.abs(st[cand] - wt[None, :])
                best = cand[np.argmin(dt, axis=0), np.arange(len(wt))]
                ok = np.min(dt, axis=0) <= borrow_s * 1e6
                near[ok] = sidx[best[ok]]
            t = np.concatenate([st, wt])
            is_scan = np.concatenate([np.ones(len(st), bool), np.zeros(len(wt), bool)])
            fp = np.concatenate([sidx, near])
            o = np.argsort(t, kind="stable")
            t, is_scan, fp = t[o], is_scan[o], fp[o]
        xy, fl = w.place(t)
        dr, path = w.dead_reckoning(t)
        is_truth = (is_scan if w.dense_truth else ~is_scan) & np.isfinite(xy[:, 0])
        parts.append((np.full(len(t), k), t, is_scan, fp, xy, fl, is_truth, dr, path))
    cols = [np.concatenate(c) for c in zip(*parts)]
    return Points(*cols)


@dataclasses.dataclass
class Problem:
    """Anchors, ranges and the initial guess; arrays as in the native call (module docstring)."""

    n: int
    anchor_index: np.ndarray
    anchor_xy: np.ndarray
    pair_i: np.ndarray
    pair_j: np.ndarray
    range_m: np.ndarray
    weight: np.ndarray
    row_kind: np.ndarray  # 0 PDR, 1 Wi-Fi
    x0: np.ndarray  # (n, 2)
    info: dict


def _wifi_pairs(
    points: Points, scans: ScanSet, model: DistanceModel, tau, block: int = 2048, collect: bool = True
):
    """Candidate Wi-Fi pairs (i > j, both with a fingerprint, same floor, a common AP):
    returns (i, j, g) of those passing the filter, the threshold [m], candidates, no-common count."""
    idx = np.flatnonzero(points.fp >= 0)
    R = scans.R[points.fp[idx]]
    p = _Prepared(R)
    fl = points.floor[idx]
    n = len(idx)
    # g is non-decreasing in d: max g = g(max d), so the threshold needs one pass for max d
    chunks, dmax, n_cand, n_nocommon = [], -np.inf, 0, 0
    thr = math.nan  # set at the end of pass 0, used by pass 1
    for pass_ in (0, 1) if collect else (0,):
        for i0 in range(0, n, block):
            ia = slice(i0, min(n, i0 + block))
            for j0 in range(0, i0 + 1, block):
                ib = slice(j0, min(n, j0 + block))
                D = _block(p, ia, p, ib, model.mode, model.min_common_aps)
                tri = np.tri(D.shape[0], D.shape[1], -1, dtype=bool) if i0 == j0 else np.ones(D.shape, bool)
                same = fl[ia][:, None] == fl[ib][None, :]
                cand = tri & same
                ok = cand & np.isfinite(D)
                if pass_ == 0:
                    n_cand += int(cand.sum())
                    n_nocommon += int((cand & ~ok).sum())
                    if ok.any():
                        dmax = max(dmax, float(D[ok].max()))
                    continue
                if tau is not None:
                    with np.errstate(invalid="ignore"):
                        ok &= model(D) <= thr
                ii, jj = np.nonzero(ok)
                chunks.append((idx[ii + i0], idx[jj + j0], model(D[ii, jj])))
        if pass_ == 0:
            thr = (
                math.nan if not np.isfinite(dmax) else (tau if tau is not None else 1.0) * float(model(dmax))
            )
    if chunks:
        i, j, g = (np.concatenate(c) for c in zip(*chunks))
    else:
        i, j, g = np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return i, j, g, thr, n_cand, n_nocommon


def build_problem(
    walks: list[Walk],
    scans: ScanSet,
    points: Points,
    *,
    model: DistanceModel | None,
    ranges: str = "both",
    anchors: str = "every:4",
    pdr_span: int = 1,
    pdr_metric: str = "chord",
    weights: tuple | None = DEFAULT_WEIGHTS,
    tau: float | None = DEFAULT_TAU,
) -> Problem:
    """Rows of the problem (module docstring). ``weights`` = (m, c) or None; ``tau`` None = no filter."""
    if ranges not in RANGES:
        raise CrowdInputError(f"ranges {ranges!r} not one of {RANGES}")
    if ranges != "pdr" and model is None:
        raise CrowdInputError(f"ranges {ranges!r} need a distance model (--model model.json)")
    if pdr_metric not in ("chord", "path"):
        raise CrowdInputError(f"pdr metric {pdr_metric!r} not chord or path")
    K = parse_anchors(anchors)
    n = len(points.t_us)
    info: dict = {
        "points": n,
        "ranges": ranges,
        "anchors": anchors,
        "pdr_span": pdr_span,
        "pdr_metric": pdr_metric,
        "weights": list(weights) if weights else None,
        "tau": tau,
    }
    # anchors: every K-th truth point of each walk
    is_anchor = np.zeros(n, bool)
    for k in range(len(walks)):
        tp = np.flatnonzero((points.walk == k) & points.is_truth)
        is_anchor[tp[::K]] = True
    a_idx = np.flatnonzero(is_anchor)
    # PDR pairs within each walk
    pi_parts: list[np.ndarray] = []
    pj_parts: list[np.ndarray] = []
    if ranges != "wifi":
        for k, w in enumerate(walks):
            if len(w.step_t_us) == 0:
                raise CrowdInputError(
                    f"{w.name}: no STEP messages (PDR ranges need the firmware "
                    f"log of the walk: give 'firmware.lcmlog,truth.lcmlog')"
                )
            ids = np.flatnonzero(points.walk == k)
            m = len(ids)
            span = m - 1 if pdr_span <= 0 else min(pdr_span, m - 1)
            for s in range(1, span + 1):
                pi_parts.append(ids[:-s])
                pj_parts.append(ids[s:])
    pi = np.concatenate(pi_parts) if pi_parts else np.zeros(0, np.int64)
    pj = np.concatenate(pj_parts) if pj_parts else np.zeros(0, np.int64)
    if pdr_metric == "chord":
        b_pdr = np.hypot(*(points.dr_xy_m[pj] - points.dr_xy_m[pi]).T)
    else:
        b_pdr = points.dr_path_m[pj] - points.dr_path_m[pi]
    info["pdr_pairs"] = int(len(pi))
    wi = wj = np.zeros(0, np.int64)
    bw = np.zeros(0)
    if ranges != "pdr":
        assert model is not None  # checked on entry: Wi-Fi ranges need a model
        use_tau = tau if ranges in ("wifi", "both") else None
        wi, wj, bw, thr, n_cand, n_nc = _wifi_pairs(points, scans, model, use_tau, collect=ranges != "hybrid")
        info.update(wifi_candidate_pairs=n_cand, wifi_pairs_no_common_ap=n_nc, wifi_threshold_m=thr)
        if ranges == "hybrid":
            keep = np.ones(len(pi), bool)
            if tau is not None:
                thr_h = tau * (thr if math.isfinite(thr) else math.inf)
                info["wifi_threshold_m"] = thr_h
                fpi, fpj = points.fp[pi], points.fp[pj]
                has = (fpi >= 0) & (fpj >= 0)
                if has.any():
                    D = _block_pairs(scans, fpi[has], fpj[has], model.mode, model.min_common_aps)
                    with np.errstate(invalid="ignore"):
                        keep[np.flatnonzero(has)] = np.isfinite(D) & (model(D) <= thr_h)
            pi, pj, b_pdr = pi[keep], pj[keep], b_pdr[keep]
            info["pdr_pairs_after_filter"] = int(len(pi))
            wi = wj = np.zeros(0, np.int64)
            bw = np.zeros(0)
        info["wifi_pairs"] = int(len(wi))
    i = np.concatenate([pi, wi]).astype(np.int64)
    j = np.concatenate([pj, wj]).astype(np.int64)
    b = np.concatenate([b_pdr, bw]).astype(float)
    kind = np.concatenate([np.zeros(len(pi), np.int8), np.ones(len(wi), np.int8)])
    weight = 1.0 / (weights[0] * b + weights[1]) if weights else np.ones(len(b))
    if weights and np.any(~np.isfinite(weight) | (weight <= 0)):
        raise CrowdInputError(
            f"weights 1/(m·b + c) with m, c = {weights} are not positive for every range (need c > −m·min b)"
        )
    x0 = _initial_guess(points, is_anchor)
    info["anchors_n"] = int(len(a_idx))
    info["unconstrained_points"] = int(n - len(np.unique(np.concatenate([i, j, a_idx]))))
    return Problem(
        n=n,
        anchor_index=a_idx,
        anchor_xy=points.truth_xy_m[a_idx],
        pair_i=i,
        pair_j=j,
        range_m=b,
        weight=weight,
        row_kind=kind,
        x0=x0,
        info=info,
    )


def _block_pairs(scans: ScanSet, a: np.ndarray, b: np.ndarray, mode: str, min_common: int = 1) -> np.ndarray:
    """Dissimilarity of scan a[k] vs scan b[k] for each k (row-wise, O(k·m))."""
    out = np.empty(len(a))
    for s in range(0, len(a), 4096):
        sl = slice(s, s + 4096)
        pa, pb = _Prepared(scans.R[a[sl]]), _Prepared(scans.R[b[sl]])
        ssum = np.einsum("ij,ij->i", pa.left, pb.right)
        nc = np.einsum("ij,ij->i", pa.M, pb.M)
        ssum = np.maximum(ssum, 0.0)
        if mode == "common_scaled":
            with np.errstate(divide="ignore", invalid="ignore"):
                ssum *= (pa.count + pb.count - nc) / nc
        d = np.sqrt(ssum)
        d[nc < max(min_common, 1) - 0.5] = np.nan
        out[sl] = d
    return out


def _initial_guess(points: Points, is_anchor: np.ndarray) -> np.ndarray:
    x0 = np.zeros((len(points.t_us), 2))
    all_a = points.truth_xy_m[is_anchor]
    fallback = all_a.mean(axis=0) if len(all_a) else np.zeros(2)
    for k in np.unique(points.walk):
        ids = np.flatnonzero(points.walk == k)
        a = ids[is_anchor[ids]]
        if len(a) == 0:
            x0[ids] = fallback
            continue
        for c in range(2):
            x0[ids, c] = np.interp(points.t_us[ids], points.t_us[a], points.truth_xy_m[a, c])
    return x0


# --- solvers ----------------------------------------------------------------------------------------


def solve_scipy(prob: Problem, max_nfev: int = DEFAULT_MAX_NFEV) -> tuple[np.ndarray, dict]:
    """Scipy reference: least_squares (trf, LSMR) on the stacked weighted residuals."""
    n, a, i, j = prob.n, prob.anchor_index, prob.pair_i, prob.pair_j
    b, w = prob.range_m, prob.weight
    na, k = len(a), len(i)
    cols_a = np.concatenate([2 * a, 2 * a + 1])
    rows_a = np.concatenate([np.arange(na), na + np.arange(na)])
    r_rng = 2 * na + np.arange(k)
    rows = np.concatenate([rows_a, np.repeat(r_rng, 4)])
    cols = np.concatenate([cols_a, np.stack([2 * i, 2 * i + 1, 2 * j, 2 * j + 1], 1).ravel()])

    def fun(x):
        p = x.reshape(n, 2)
        dxy = p[i] - p[j]
        dist = np.hypot(dxy[:, 0], dxy[:, 1])
        ra = (p[a] - prob.anchor_xy).T.ravel()
        return np.concatenate([ra, w * (b - dist)])

    def jac(x):
        p = x.reshape(n, 2)
        dxy = p[i] - p[j]
        dist = np.maximum(np.hypot(dxy[:, 0], dxy[:, 1]), 1e-9)
        u = dxy / dist[:, None] * w[:, None]
        vals = np.concatenate([np.ones(2 * na), np.stack([-u[:, 0], -u[:, 1], u[:, 0], u[:, 1]], 1).ravel()])
        return sp.csr_matrix((vals, (rows, cols)), shape=(2 * na + k, 2 * n))

    t0 = time.perf_counter()
    res = least_squares(fun, prob.x0.ravel(), jac=jac, method="trf", tr_solver="lsmr", max_nfev=max_nfev)
    name = "scipy least_squares (trf, lsmr)"
    return res.x.reshape(n, 2), {
        "solver": name,
        "nfev": int(res.nfev),
        "cost": float(res.cost),
        "status": int(res.status),
        "solve_s": time.perf_counter() - t0,
    }


def solve_native(prob: Problem, max_iterations: int = 1000) -> tuple[np.ndarray, dict]:
    """``stridefix_native.solve_coordinates`` (C++/Ceres); raises when it is missing or fails."""
    import stridefix_native  # noqa: PLC0415 - optional

    t0 = time.perf_counter()
    out = stridefix_native.solve_coordinates(
        int(prob.n),
        prob.anchor_index.astype(np.int64),
        np.ascontiguousarray(prob.anchor_xy, float),
        np.ascontiguousarray(np.column_stack([prob.pair_i, prob.pair_j]).astype(np.int64)),
        prob.range_m.astype(float),
        prob.weight.astype(float),
        init_xy=np.ascontiguousarray(prob.x0, float),
        max_iterations=int(max_iterations),
    )
    xy = np.asarray(out["xy"], float).reshape(prob.n, 2)
    return xy, {
        "solver": "stridefix_native.solve_coordinates (Ceres)",
        "solve_s": time.perf_counter() - t0,
        "iterations": out.get("iterations"),
        "converged": out.get("converged"),
        "cost": out.get("cost"),
        "message": out.get("message"),
    }


def solve(prob: Problem, solver: str = "auto") -> tuple[np.ndarray, dict]:
    """Solve with ``solver`` (auto = native when importable, else scipy); info says which ran."""
    if solver not in SOLVERS:
        raise CrowdInputError(f"solver {solver!r} not one of {SOLVERS}")
    note = None
    if solver in ("auto", "native"):
        try:
            xy, info = solve_native(prob)
            if not np.all(np.isfinite(xy)):
                raise ValueError("non-finite positions")
            return xy, info
        except Exception as exc:  # noqa: BLE001 - any native failure falls back (reported)
            if solver == "native":
                raise CrowdInputError(f"native solver unavailable or failed: {exc!r}") from exc
            note = f"native solver not used ({type(exc).__name__}: {str(exc)[:200]})"
    xy, info = solve_scipy(prob)
    if note:
        info["note"] = note
    return xy, info


class Anchored(Protocol):
    """What :func:`error_stats` reads of a solve: which points were anchors (a :class:`Problem` or a
    :class:`.graph_run.GraphRun`)."""

    @property
    def anchor_index(self) -> np.ndarray: ...

    @property
    def n(self) -> int: ...


def error_stats(xy: np.ndarray, points: Points, prob: Anchored) -> dict:
    """Errors at the non-anchor truth points (and, for thesis parity, over all truth points)."""
    is_anchor = np.zeros(prob.n, bool)
    is_anchor[prob.anchor_index] = True
    truth = points.is_truth
    e_all = np.hypot(*(xy[truth] - points.truth_xy_m[truth]).T)
    e = np.hypot(*(xy[truth & ~is_anchor] - points.truth_xy_m[truth & ~is_anchor]).T)
    if e.size == 0:
        return {"n": 0}
    return {
        "n": int(e.size),
        "mean_m": float(e.mean()),
        "std_m": float(e.std(ddof=1)) if e.size > 1 else 0.0,
        "median_m": float(np.median(e)),
        "p90_m": float(np.percentile(e, 90)),
        "rmse_m": float(np.sqrt(np.mean(e * e))),
        "max_m": float(e.max()),
        "mean_all_m": float(e_all.mean()),
        "n_all": int(e_all.size),
    }
