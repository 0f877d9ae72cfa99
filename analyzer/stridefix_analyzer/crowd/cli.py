"""``stridefix crowd``: the crowdsourced Wi-Fi model of Kannan (2024) on StrideFix logs.

``fit``        dissimilarity → distance model g(d) = max(X1, X2 + X3·d) from walks with ground truth:
               every scan pair on a floor (positions interpolated on the truth), exact streaming
               binning, bounded least squares on the bins → ``model.json`` + ``model_fit.png``.
``solve``      2-D positions of the points of a set of walks from anchors (a subset of the truth
               points) and range rows from PDR and/or the Wi-Fi model → ``solve.json``,
               ``positions.csv``, ``solve.png``; error at the non-anchor truth points.
``radiomap``   a site file built from the solved positions instead of the truth (the walk-mode builder
               of ``stridefix radiomap``); ``--truth-site`` also writes the truth-built one.
``experiment`` the thesis's table in SIL (``--sil``) or on msindoor walks (``--msindoor DIR``), see
               :mod:`.crowd_experiment`.

Logs: an argument ``a.lcmlog,b.lcmlog`` is one walk (e.g. ``stridefixd.lcmlog,truth.lcmlog`` of a SIL
run, or the firmware's replay log with the imported msindoor log); see :mod:`.crowd_walks`. The
modules: :mod:`.crowd_model` (dissimilarity, binning, fit, filter), :mod:`.crowd_walks` (loading),
:mod:`.crowd_solve` (problem, solvers, errors), :mod:`.crowd_plots`.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd.solve import RANGES, SOLVERS, build_problem, error_stats, make_points, solve
from stridefix_analyzer.crowd.walks import BANDS, DEFAULT_BAND, CrowdInputError, Walk, load_walks, pool_scans
from stridefix_analyzer.io.logread import LogReadError, Table

DEFAULT_OUT = os.path.join("out", "crowd")


# --- fit ---------------------------------------------------------------------------------------------


def fit_walks(
    walks: list[Walk],
    mode: str = cm.DEFAULT_MODE,
    band: str = DEFAULT_BAND,
    width_db: float = cm.DEFAULT_BIN_WIDTH_DB,
    min_common: int = 1,
) -> tuple[cm.DistanceModel, cm.PairBins]:
    """Fit g on every pair of placed scans on the same floor of ``walks`` (streaming binning)."""
    t0 = time.perf_counter()
    scans = pool_scans(walks, band)
    use = scans.usable & np.isfinite(scans.xy_m[:, 0])
    if use.sum() < 3:
        raise CrowdInputError(
            f"only {int(use.sum())} scan(s) with truth and an AP in band {band}: nothing to fit"
        )
    bins = cm.bin_pairs(
        scans.R[use], scans.xy_m[use], scans.floor[use], mode=mode, width_db=width_db, min_common=min_common
    )
    model = cm.fit_binned(bins, mode)
    model.min_common_aps = int(min_common)
    if not model.r2 > 0 or model.slope_m_per_db < 1e-6:
        model.extra["warning"] = (
            f"degenerate fit (R² {model.r2:.2f}, X3 {model.slope_m_per_db:.2g}): distance does not "
            f"grow with dissimilarity within the bounds X1 ≤ min distance, X2 ≤ 0 (the ordinary "
            f"line is d = {model.ols_start[0]:.2f} + {model.ols_start[1]:.4f}·x); try "
            f"--dissimilarity common_scaled and/or --min-common-aps"
        )
    model.extra.update(
        band=band,
        walks=len(walks),
        scans=int(use.sum()),
        aps=int(np.isfinite(scans.R[use]).any(axis=0).sum()),
        floors=sorted(int(f) for f in np.unique(scans.floor[use])),
        fit_s=time.perf_counter() - t0,
    )
    return model, bins


def format_model(m: cm.DistanceModel) -> str:
    e = m.extra
    return (
        f"g(d) = max(X1, X2 + X3·d): X1 = {m.floor_m:.3f} m, X2 = {m.intercept_m:.3f} m, "
        f"X3 = {m.slope_m_per_db:.4f} m/dB  (RMSE {m.rmse_m:.2f} m, R² {m.r2:.3f}; "
        f"{m.n_pairs} pairs of {e.get('scans', '?')} scans, {e.get('aps', '?')} APs, band "
        f"{e.get('band', '?')}, {m.mode}; {e.get('n_pairs_no_common_ap', 0)} pairs with fewer "
        f"than {m.min_common_aps} common AP(s) excluded; {e.get('fit_s', math.nan):.1f} s)\n  method: {m.method}"
        + (f"\n  WARNING: {e['warning']}" if e.get("warning") else "")
    )


def run_fit(args) -> dict:
    walks = load_walks(args.logs)
    model, bins = fit_walks(walks, args.dissimilarity, args.band, args.bin_width_db, args.min_common_aps)
    os.makedirs(args.out, exist_ok=True)
    doc = model.to_json()
    doc["inputs"] = [w.name for w in walks]
    path = os.path.join(args.out, "model.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    from stridefix_analyzer.crowd.plots import plot_fit

    png = os.path.join(args.out, "model_fit.png")
    plot_fit(bins, model, png)
    print(format_model(model))
    print(f"wrote {path} and {png}")
    return doc


def read_model(path: str) -> cm.DistanceModel:
    try:
        with open(path) as f:
            return cm.DistanceModel.from_json(json.load(f))
    except (OSError, ValueError, TypeError) as exc:
        raise CrowdInputError(f"{path}: cannot read a distance model ({exc})") from exc


# --- solve -------------------------------------------------------------------------------------------


def solve_walks(
    walks: list[Walk],
    model: cm.DistanceModel | None,
    *,
    ranges: str,
    anchors: str,
    pdr_span: int = 1,
    pdr_metric: str = "chord",
    weights=(1.0, 2.0),
    tau: float | None = cm.DEFAULT_TAU,
    band: str = DEFAULT_BAND,
    solver: str = "auto",
    step_scale: float = 1.0,
):
    """Build and solve one problem; returns (positions (n, 2), points, problem, result dict)."""
    t0 = time.perf_counter()
    if step_scale != 1.0:
        for w in walks:
            w.step_length_m = w.step_length_m * step_scale
    try:
        scans = pool_scans(walks, band)
        points = make_points(walks, scans)
        prob = build_problem(
            walks,
            scans,
            points,
            model=model,
            ranges=ranges,
            anchors=anchors,
            pdr_span=pdr_span,
            pdr_metric=pdr_metric,
            weights=weights,
            tau=tau,
        )
    finally:
        if step_scale != 1.0:
            for w in walks:
                w.step_length_m = w.step_length_m / step_scale
    build_s = time.perf_counter() - t0
    xy, sinfo = solve(prob, solver)
    res = {
        "problem": prob.info,
        "solver": sinfo,
        "error": error_stats(xy, points, prob),
        "build_s": build_s,
        "rows": {
            "anchors": int(len(prob.anchor_index)),
            "pdr": int(np.sum(prob.row_kind == 0)),
            "wifi": int(np.sum(prob.row_kind == 1)),
        },
    }
    return xy, points, prob, res


def _weights(args):
    return None if args.no_weights else (args.weight_m, args.weight_c)


def _tau(args):
    return None if args.no_filter else args.tau


def run_solve(args) -> dict:
    walks = load_walks(args.logs)
    model = read_model(args.model) if args.model else None
    xy, points, prob, res = solve_walks(
        walks,
        model,
        ranges=args.ranges,
        anchors=args.anchors,
        pdr_span=args.pdr_span,
        pdr_metric=args.pdr_metric,
        weights=_weights(args),
        tau=_tau(args),
        band=args.band,
        solver=args.solver,
        step_scale=args.step_scale,
    )
    os.makedirs(args.out, exist_ok=True)
    res["inputs"] = [w.name for w in walks]
    with open(os.path.join(args.out, "solve.json"), "w") as f:
        json.dump(res, f, indent=2, default=float)
        f.write("\n")
    write_positions(os.path.join(args.out, "positions.csv"), xy, points, prob)
    from stridefix_analyzer.crowd.plots import plot_solution

    e = res["error"]
    plot_solution(
        xy,
        points.truth_xy_m,
        points.is_truth,
        prob.anchor_index,
        os.path.join(args.out, "solve.png"),
        f"{args.ranges}: mean error {e.get('mean_m', math.nan):.2f} m, std {e.get('std_m', math.nan):.2f} m",
    )
    print(format_solve(res))
    print(f"wrote {args.out}/solve.json, positions.csv, solve.png")
    return res


def format_solve(res: dict) -> str:
    p, s, e, r = res["problem"], res["solver"], res["error"], res["rows"]
    lines = [
        f"problem  {p['points']} points, {r['anchors']} anchors ({p['anchors']}), "
        f"{r['pdr']} PDR rows (span {p['pdr_span']}, {p['pdr_metric']}), {r['wifi']} Wi-Fi rows; "
        f"ranges {p['ranges']}, weights {p['weights']}, tau {p['tau']}"
        + (
            f", Wi-Fi threshold {p['wifi_threshold_m']:.2f} m"
            if p.get("wifi_threshold_m") is not None and np.isfinite(p.get("wifi_threshold_m", math.nan))
            else ""
        ),
        f"solver   {s['solver']} ({s['solve_s']:.2f} s)" + (f"; {s['note']}" if "note" in s else ""),
    ]
    if e.get("n"):
        lines.append(
            f"error    at {e['n']} non-anchor truth points: mean {e['mean_m']:.2f} m, std "
            f"{e['std_m']:.2f} m, median {e['median_m']:.2f} m, p90 {e['p90_m']:.2f} m, "
            f"RMSE {e['rmse_m']:.2f} m (incl. anchors, as the thesis: mean "
            f"{e['mean_all_m']:.2f} m)"
        )
    return "\n".join(lines)


def write_positions(path: str, xy, points, prob) -> None:
    is_anchor = np.zeros(prob.n, bool)
    is_anchor[prob.anchor_index] = True
    with open(path, "w") as f:
        f.write("walk,t_us,is_scan,is_truth,is_anchor,x_m,y_m,x_gt_m,y_gt_m\n")
        for k in range(prob.n):
            f.write(
                f"{points.walk[k]},{points.t_us[k]},{int(points.is_scan[k])},"
                f"{int(points.is_truth[k])},{int(is_anchor[k])},{xy[k, 0]:.3f},{xy[k, 1]:.3f},"
                f"{points.truth_xy_m[k, 0]:.3f},{points.truth_xy_m[k, 1]:.3f}\n"
            )


# --- radio map from the crowd ------------------------------------------------------------------------


def crowd_recordings(walks: list[Walk], xy: np.ndarray | None, points):
    """radiomap Recordings of ``walks`` whose TRUTH is the solved position at each scan time
    (``xy`` None: the real truth at the scan times, for the comparison map)."""
    from stridefix_analyzer.radiomap.build import Recording

    recs = []
    for k, w in enumerate(walks):
        sel = (points.walk == k) & points.is_scan
        t = points.t_us[sel]
        if xy is None:
            p, _ = w.place(t)
        else:
            p = xy[sel]
        _, fl = w.place(t)
        ok = np.isfinite(p[:, 0])
        truth = Table(
            {
                "t_us": t[ok],
                "x_m": p[ok, 0],
                "y_m": p[ok, 1],
                "floor": np.where(fl[ok] < -9000, 0, fl[ok]).astype(np.int64),
                "heading_rad": np.full(int(ok.sum()), np.nan),
                "step_count": np.full(int(ok.sum()), -1, np.int64),
                "source": np.full(int(ok.sum()), 1, np.int64),
            }
        )
        wifi = Table(
            {
                "t_us": w.scan_t_us,
                "scan_id": np.arange(w.n_scans),
                "complete": w.scan_complete if w.scan_complete is not None else np.ones(w.n_scans, bool),
                "n_ap": np.bincount(w.ap_scan, minlength=w.n_scans),
            }
        )
        ap = Table(
            {"scan_row": w.ap_scan, "bssid": w.ap_bssid, "rssi_dbm": w.ap_rssi_dbm, "freq_mhz": w.ap_freq_mhz}
        )
        recs.append(Recording([w.name], wifi, ap, truth.sorted_by("t_us")))
    return recs


def build_crowd_sites(
    walks,
    xy,
    points,
    out_site: str,
    truth_site: str | None = None,
    cell_size_m: float = 2.0,
    map_rotation_deg: float = 0.0,
) -> dict:
    """Write the crowd-built site (and the truth-built one); return their summaries."""
    from stridefix_analyzer.io.sitefile import write_site
    from stridefix_analyzer.radiomap.build import build_site

    out = {}
    for path, pos, label in ((out_site, xy, "crowd"), (truth_site, None, "truth")):
        if path is None:
            continue
        site, summary = build_site(
            crowd_recordings(walks, pos, points),
            mode="walk",
            cell_size_m=cell_size_m,
            name=f"crowd-{label}",
            map_rotation_deg=map_rotation_deg,
        )
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        summary["bytes"] = write_site(path, site)
        out[label] = {
            "path": path,
            "n_rp": summary["n_rp"],
            "n_ap": summary["n_ap"],
            "scans_used": summary["scans"]["used"],
        }
    return out


def run_radiomap(args) -> dict:
    walks = load_walks(args.logs)
    model = read_model(args.model) if args.model else None
    xy, points, prob, res = solve_walks(
        walks,
        model,
        ranges=args.ranges,
        anchors=args.anchors,
        pdr_span=args.pdr_span,
        pdr_metric=args.pdr_metric,
        weights=_weights(args),
        tau=_tau(args),
        band=args.band,
        solver=args.solver,
        step_scale=args.step_scale,
    )
    print(format_solve(res))
    sites = build_crowd_sites(
        walks, xy, points, args.out, args.truth_site, args.cell_size_m, args.map_rotation_deg
    )
    for label, s in sites.items():
        print(f"{label:5} site {s['path']}: {s['n_rp']} RPs, {s['n_ap']} APs, {s['scans_used']} scans")
    return {"solve": res, "sites": sites}


# --- command line ------------------------------------------------------------------------------------


def _common(p, solve_opts: bool) -> None:
    p.add_argument(
        "logs",
        nargs="+",
        metavar="LOG",
        help="walks: 'a.lcmlog,b.lcmlog' = one walk (firmware log + truth log)",
    )
    p.add_argument(
        "--band",
        choices=BANDS,
        default=DEFAULT_BAND,
        help=f"APs used: 2.4 GHz only as the thesis, or all (default {DEFAULT_BAND})",
    )
    if not solve_opts:
        return
    p.add_argument(
        "--model",
        default=None,
        metavar="model.json",
        help="distance model from `crowd fit` (needed unless --ranges pdr)",
    )
    p.add_argument(
        "--anchors",
        default="every:4",
        metavar="every:K|every-other-waypoint",
        help="known truth points per walk (default every:4, the thesis)",
    )
    p.add_argument(
        "--ranges",
        choices=RANGES,
        default="both",
        help="pdr; wifi; both = PDR + filtered Wi-Fi rows; hybrid = PDR rows filtered "
        "by Wi-Fi (the thesis's PDR + Wi-Fi) (default both)",
    )
    p.add_argument(
        "--pdr-span",
        type=int,
        default=1,
        help="PDR rows between points at most this far apart in a walk (1 = "
        "consecutive, 2 = thesis filtering, 0 = all pairs) (default 1)",
    )
    p.add_argument(
        "--pdr-metric",
        choices=("chord", "path"),
        default="chord",
        help="PDR distance: dead-reckoned chord, or Σ step lengths (default chord)",
    )
    p.add_argument(
        "--step-scale",
        type=float,
        default=1.0,
        help="multiply the firmware's step lengths (stride calibration) (default 1)",
    )
    p.add_argument(
        "--tau",
        type=float,
        default=cm.DEFAULT_TAU,
        help=f"reliability filter: keep g(d) ≤ tau·max (default {cm.DEFAULT_TAU})",
    )
    p.add_argument("--no-filter", action="store_true", help="no reliability filter")
    p.add_argument("--weight-m", type=float, default=1.0, help="weights 1/(m·b + c): m (default 1)")
    p.add_argument("--weight-c", type=float, default=2.0, help="c (default 2)")
    p.add_argument("--no-weights", action="store_true", help="all range rows weight 1")
    p.add_argument(
        "--solver",
        choices=SOLVERS,
        default="auto",
        help="native (stridefix_native, Ceres), scipy, or auto = native when importable (default)",
    )


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "crowd",
        help="crowdsourced Wi-Fi model (Kannan 2024): fit, solve, radio map, experiment",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="crowd_command", metavar="ACTION", required=True)
    f = sub.add_parser("fit", help="fit g(d) on walks with truth → model.json + plot")
    _common(f, False)
    f.add_argument("--out", required=True, metavar="DIR")
    f.add_argument(
        "--dissimilarity",
        choices=cm.MODES,
        default=cm.DEFAULT_MODE,
        help=f"common_sum (thesis Eq. 4) or common_scaled (× n/n*, n = union) (default {cm.DEFAULT_MODE})",
    )
    f.add_argument(
        "--bin-width-db",
        type=float,
        default=cm.DEFAULT_BIN_WIDTH_DB,
        help=f"dissimilarity bin of the streaming fit [dB] (default {cm.DEFAULT_BIN_WIDTH_DB:g})",
    )
    f.add_argument(
        "--min-common-aps",
        type=int,
        default=1,
        help="pairs sharing fewer APs are excluded (default 1, the thesis); the model "
        "file records it and solve uses it",
    )
    s = sub.add_parser("solve", help="positions of the walks' points from anchors + ranges")
    _common(s, True)
    s.add_argument("--out", required=True, metavar="DIR")
    r = sub.add_parser("radiomap", help="site file from solved positions (+ a truth-built one)")
    _common(r, True)
    r.add_argument("--out", required=True, metavar="SITE.sfsite")
    r.add_argument(
        "--truth-site",
        default=None,
        metavar="SITE.sfsite",
        help="also write the site built from the truth at the same scans",
    )
    r.add_argument("--cell-size-m", type=float, default=2.0, help="walk-mode grid cell [m]")
    r.add_argument("--map-rotation-deg", type=float, default=0.0)
    e = sub.add_parser("experiment", help="the thesis's table: --sil or --msindoor DIR")
    from stridefix_analyzer.crowd.experiment import add_arguments

    add_arguments(e)
    return p


def run(args: argparse.Namespace) -> int:
    prog = f"stridefix crowd {args.crowd_command}"
    try:
        if args.crowd_command == "fit":
            run_fit(args)
        elif args.crowd_command == "solve":
            run_solve(args)
        elif args.crowd_command == "radiomap":
            run_radiomap(args)
        else:
            from stridefix_analyzer.crowd.experiment import run_experiment

            return run_experiment(args)
    except (LogReadError, CrowdInputError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    return 0
