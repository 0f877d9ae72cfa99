"""``stridefix crowd radiomap``: a site file built from the solved positions instead of the truth.

The walk-mode builder of ``stridefix radiomap`` on recordings whose TRUTH is the crowd's solved
position at each scan; ``--truth-site`` also writes the truth-built one, for comparison.
"""

from __future__ import annotations

import argparse
import os
from typing import Any

import numpy as np

from stridefix_analyzer.crowd.positions import format_solve, solve_args
from stridefix_analyzer.crowd.walks import Walk, load_walks
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.io.sitefile import write_site
from stridefix_analyzer.radiomap.build import Recording, build_site


def crowd_recordings(walks: list[Walk], xy: np.ndarray | None, points):
    """radiomap Recordings of ``walks`` whose TRUTH is the solved position at each scan time
    (``xy`` None: the real truth at the scan times, for the comparison map)."""
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


def run_radiomap(args: argparse.Namespace) -> dict[str, Any]:
    walks = load_walks(args.logs)
    xy, points, prob, res = solve_args(args, walks)
    print(format_solve(res))
    sites = build_crowd_sites(
        walks, xy, points, args.out, args.truth_site, args.cell_size_m, args.map_rotation_deg
    )
    for label, s in sites.items():
        print(f"{label:5} site {s['path']}: {s['n_rp']} RPs, {s['n_ap']} APs, {s['scans_used']} scans")
    return {"solve": res, "sites": sites}
