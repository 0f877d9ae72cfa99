"""``stridefix crowd radiomap``: a site file built from the crowd's solved positions instead of the truth.

The positions come from the graph (:func:`.graph_run.solve_walks_graph`: every K-th truth point of each
walk as an anchor, the walk's STEP messages between them; Kannan 2024 §4 anchors every 4th waypoint),
and the map is the walk-mode builder of ``stridefix radiomap`` on recordings whose TRUTH is the solved
position at each point (:func:`solved_truth`). ``--truth-site`` also writes the truth-built one from the
same scans, for comparison; ``SITE.solve.json`` records the rows used and the solve's error at the
non-anchor truth points. realbench's crowd-built fold sites (:mod:`..realbench.crowdmap`) use the
same :func:`solved_truth`.
"""

from __future__ import annotations

import argparse
import json
import os
from types import SimpleNamespace
from typing import Any

import numpy as np

from stridefix_analyzer.crowd.graph_run import GraphRun, solve_walks_graph
from stridefix_analyzer.crowd.solve import Points, error_stats
from stridefix_analyzer.crowd.walks import Walk, load_walks
from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.io.sitefile import write_site
from stridefix_analyzer.radiomap.build import Recording, build_site


def solved_truth(walk: Walk, k: int, xy_m: np.ndarray, points: Points) -> Table:
    """A TRUTH table of walk ``k`` whose rows are its points at their solved positions ``xy_m``.

    Only points inside the walk's truth span with a known floor (the floor is the truth's: the crowd
    solve is 2-D), so the radio-map builder skips exactly the scans it skips on the truth; a scan at a
    point gets its solved position, any other scan the interpolation between solved points."""
    sel = points.walk == k
    t = points.t_us[sel]
    p = xy_m[sel]
    _, fl = walk.place(t)
    ok = np.isfinite(p[:, 0]) & (fl > -9000)
    if len(walk.truth_t_us):
        ok &= (t >= walk.truth_t_us[0]) & (t <= walk.truth_t_us[-1])
    n = int(ok.sum())
    return Table(
        {
            "t_us": t[ok],
            "x_m": p[ok, 0],
            "y_m": p[ok, 1],
            "floor": fl[ok].astype(np.int64),
            "heading_rad": np.full(n, np.nan),
            "step_count": np.full(n, -1, np.int64),
            "source": np.full(n, 1, np.int64),
        }
    ).sorted_by("t_us")


def crowd_recordings(walks: list[Walk], xy: np.ndarray | None, points: Points) -> list[Recording]:
    """radiomap Recordings of ``walks`` whose TRUTH is the solved position at each scan time
    (``xy`` None: the real truth at the scan times, for the comparison map)."""
    recs = []
    for k, w in enumerate(walks):
        if xy is None:
            sel = (points.walk == k) & points.is_scan
            t = points.t_us[sel]
            p, fl = w.place(t)
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
            ).sorted_by("t_us")
        else:
            truth = solved_truth(w, k, xy, points)
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
        recs.append(Recording([w.name], wifi, ap, truth))
    return recs


def scan_sigma_m(run: GraphRun, sigma_m: np.ndarray, k: int, scan_t_us: np.ndarray) -> np.ndarray:
    """Posterior σ [m] (:func:`.graph_solve.position_sigma_m` of ``run``) of walk ``k`` at each scan
    time: the point's own σ at a scan that is a point, else interpolated in time between the walk's
    points (NaN for a walk without points)."""
    sel = run.points.walk == k
    t, s = run.points.t_us[sel], sigma_m[sel]
    ok = np.isfinite(s)
    if not ok.any():
        return np.full(len(scan_t_us), np.nan)
    return np.interp(np.asarray(scan_t_us, float), t[ok].astype(float), s[ok])


def drop_uncertain_scans(rec: Recording, sigma_m: np.ndarray, max_sigma_m: float) -> tuple[Recording, int]:
    """``rec`` without the scans whose position σ (``sigma_m``, one per scan) exceeds ``max_sigma_m``
    (a NaN σ is unknown: dropped too), and how many were dropped. The AP rows follow their scans."""
    keep = np.asarray(sigma_m, float) <= max_sigma_m
    if max_sigma_m == np.inf or keep.all():
        return rec, 0
    new_row = np.cumsum(keep) - 1
    ap_keep = keep[rec.wifi_ap["scan_row"]]
    ap = rec.wifi_ap.rows(ap_keep)
    ap = Table(ap.to_dict() | {"scan_row": new_row[ap["scan_row"]]})
    return Recording(rec.files, rec.wifi.rows(keep), ap, rec.truth, rec.ble), int((~keep).sum())


def graph_errors(run: GraphRun) -> dict[str, Any]:
    """The solve's error at the non-anchor truth points (:func:`.solve.error_stats`), and that of the
    anchors interpolated in time (the graph's initial guess, what a map without PDR would use)."""
    prob = SimpleNamespace(anchor_index=run.problem.anchor_idx, n=run.problem.n_points)
    return {
        "graph": error_stats(run.xy_m, run.points, prob),
        "interpolated": error_stats(run.problem.init_xy_m, run.points, prob),
    }


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


def format_graph_run(run: GraphRun, errors: dict[str, Any]) -> str:
    """The rows used and the errors at the non-anchor truth points, for the console."""
    r, s = run.info["rows"], run.info["solver"]
    lines = [
        f"graph    {run.problem.n_points} points of {run.problem.n_walks} walks: {r['anchors']} anchors, "
        f"{r['steps']} step rows, {r['heading']} heading rows, {r['wifi']} Wi-Fi rows",
        f"solver   {s.get('solver')} ({s.get('solve_s', float('nan')):.2f} s)"
        + (f"; {s['note']}" if "note" in s else ""),
    ]
    g, i = errors["graph"], errors["interpolated"]
    if g.get("n"):
        lines.append(
            f"error    at {g['n']} non-anchor truth points: graph mean {g['mean_m']:.2f} m (p90 "
            f"{g['p90_m']:.2f} m), anchors interpolated mean {i['mean_m']:.2f} m (p90 {i['p90_m']:.2f} m)"
        )
    return "\n".join(lines)


def run_radiomap(args: argparse.Namespace) -> dict[str, Any]:
    walks = load_walks(args.logs)
    run = solve_walks_graph(walks, anchors=args.anchors, band=args.band, solver=args.solver)
    errors = graph_errors(run)
    print(format_graph_run(run, errors))
    sites = build_crowd_sites(
        walks, run.xy_m, run.points, args.out, args.truth_site, args.cell_size_m, args.map_rotation_deg
    )
    for label, s in sites.items():
        print(f"{label:5} site {s['path']}: {s['n_rp']} RPs, {s['n_ap']} APs, {s['scans_used']} scans")
    res = {
        "inputs": [w.name for w in walks],
        "anchors": args.anchors,
        "rows": run.info["rows"],
        "solver": run.info["solver"],
        "error": errors,
        "sites": sites,
    }
    record = os.path.splitext(args.out)[0] + ".solve.json"
    with open(record, "w", encoding="utf-8") as f:
        json.dump(json_ready(res), f, indent=1)
        f.write("\n")
    print(f"wrote {record}")
    return res
