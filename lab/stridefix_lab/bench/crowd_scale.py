"""``stridefix-lab bench crowd-scale``: the crowd fit and solve at fleet scale, serial and on Dask.

The target: fit and solve for 100 000 scans / 500 walks within a few minutes on 2 cores. A
synthetic fleet (:mod:`stridefix_lab.crowd.fleet`: log-distance radio, piecewise-straight walks,
biased dead reckoning, waypoints every ~10 s) is generated in this process; then

* **fit** (:func:`.crowd.fit.fit_walks`): every scan pair of a floor (or ``--pair-fraction`` of them,
  an unbiased random subsample), float32 pair blocks, exact streaming binning, bounded least squares;
  run serially, on a LocalCluster of 1 worker and of 2 workers (or on ``--scheduler ADDRESS``). The
  cluster start is timed apart from the fit; the three bins must be bit-identical (checked, reported);
* **solve** (:func:`.crowd.scale_solve.solve_walks_grouped`): the graph of every walk (steps, heading,
  scale, anchors every 4th waypoint; no Wi-Fi rows, so groups of walks are independent tasks), serially
  and on 2 workers; Ceres when ``stridefix_native.solve_graph`` is importable, else the scipy twin
  (the JSON names which).

Target: fit (2 workers) + solve (2 workers) ≤ 300 s. Peak RSS: this process and the largest Dask worker (its own
``getrusage``). The serial runs may use 2 cores through BLAS threads; the workers are single-threaded.
Writes ``crowd_scale.json``.
"""

from __future__ import annotations

import argparse
import json
import resource
import time
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer.crowd.fit import fit_walks
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.parallel import dask_client
from stridefix_analyzer.scoring.targets import missed_lines, table_lines

from stridefix_lab.bench.registry import Bench
from stridefix_lab.crowd.fleet import FleetSpec, make_fleet
from stridefix_lab.crowd.scale_solve import solve_walks_grouped

TARGET_S = 300.0
DEFAULT_SCANS = 100_000
DEFAULT_WALKS = 500


def _rss_mb(who: int) -> float:
    return resource.getrusage(who).ru_maxrss / 1024.0  # Linux: KiB


def _worker_rss_mb() -> float:
    return _rss_mb(resource.RUSAGE_SELF)


def _same_bins(a, b) -> bool:
    return (
        all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("count", "sum_x", "sum_d", "sum_d2"))
        and a.min_d == b.min_d
        and a.n_pairs == b.n_pairs
        and a.n_no_common == b.n_no_common
    )


def run_crowd_scale(
    out: Path,
    n_scans: int = DEFAULT_SCANS,
    n_walks: int = DEFAULT_WALKS,
    scheduler: str = "local",
    pair_fraction: float = 1.0,
    solve_groups: str = "chunk:1",
    seed: int = 1,
) -> dict[str, Any]:
    """Runs the bench (module docstring); returns (and writes) the document."""
    t0 = time.perf_counter()
    fleet = make_fleet(FleetSpec(n_walks=n_walks, n_scans=n_scans, seed=seed))
    gen_s = time.perf_counter() - t0
    walks = fleet.walks
    kw: dict[str, Any] = {"pair_fraction": pair_fraction, "precision": "float32", "seed": seed}
    fits: dict[str, Any] = {}
    t = time.perf_counter()
    model, bins0 = fit_walks(walks, **kw)
    fits["serial"] = {"fit_s": time.perf_counter() - t, "identical": True}
    runs = [("dask_1", 1), ("dask_2", 2)] if scheduler == "local" else [("dask_scheduler", 0)]
    solve: dict[str, Any] = {}
    worker_rss: list[float] = []
    for name, nw in runs:
        t = time.perf_counter()
        with dask_client(scheduler, max(nw, 1)) as client:
            start_s = time.perf_counter() - t
            t = time.perf_counter()
            _m, b = fit_walks(walks, client=client, **kw)
            fits[name] = {
                "fit_s": time.perf_counter() - t,
                "cluster_start_s": start_s,
                "identical": _same_bins(b, bins0),
            }
            if name != "dask_1":
                res = solve_walks_grouped(walks, solve_groups, client=client)
                solve[name] = {k: v for k, v in res.items() if k != "xy_m"}
            worker_rss += [float(v) for v in client.run(_worker_rss_mb).values()]
    res = solve_walks_grouped(walks, solve_groups)
    solve["serial"] = {k: v for k, v in res.items() if k != "xy_m"}
    par = "dask_2" if "dask_2" in fits else "dask_scheduler"
    total = fits[par]["fit_s"] + solve[par]["solve_s"]
    e = model.extra
    doc: dict[str, Any] = {
        "fleet": {
            "scans": int(e["scans"]),
            "walks": n_walks,
            "aps": int(e["aps"]),
            "floors": e["floors"],
            "spec": {k: v for k, v in vars(fleet.spec).items()},
            "generate_s": gen_s,
        },
        "model": {"X": list(model.params), "rmse_m": model.rmse_m, "r2": model.r2, "method": model.method},
        "pairs_binned": int(bins0.n_pairs),
        "binning": e["binning"],
        "fit": fits,
        "solve": solve,
        "peak_rss_mb": {"main": _rss_mb(resource.RUSAGE_SELF), "workers": max(worker_rss, default=0.0)},
        "scheduler": scheduler,
        "targets": [
            {
                "figure": f"fit + solve on {par} ({e['scans']} scans, {n_walks} walks) [s]",
                "value": total,
                "target": f"<= {TARGET_S:g}",
                "met": bool(total <= TARGET_S),
            },
            {
                "figure": "bins bit-identical serial vs Dask",
                "value": all(f["identical"] for f in fits.values()),
                "target": "True",
                "met": all(f["identical"] for f in fits.values()),
            },
        ],
        "run_s": time.perf_counter() - t0,
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "crowd_scale.json").write_text(json.dumps(doc, indent=1, default=str))
    return doc


def format_table(doc: dict[str, Any]) -> str:
    f, b = doc["fleet"], doc["binning"]
    lines = [
        f"crowd scale: {f['scans']} scans, {f['walks']} walks, {f['aps']} APs on {len(f['floors'])} floors "
        f"(generated in {f['generate_s']:.1f} s); {doc['pairs_binned']:,} pairs binned "
        f"({b['block_pairs']} of {b['block_pairs_total']} block pairs of {b['block']}, {b['dtype']})",
        f"  {'run':<16}{'fit [s]':>9}{'start [s]':>11}{'bins =':>8}{'solve [s]':>11}{'solver':>10}",
    ]
    for name, fit in doc["fit"].items():
        s = doc["solve"].get(name)
        solver = "-" if s is None else ("ceres" if any("Ceres" in x for x in s["solver"]) else "scipy")
        lines.append(
            f"  {name:<16}{fit['fit_s']:>9.1f}{fit.get('cluster_start_s', 0.0):>11.1f}"
            f"{'yes' if fit['identical'] else 'NO':>8}{'-' if s is None else format(s['solve_s'], '.1f'):>11}{solver:>10}"
        )
    s = doc["solve"]["serial"]
    err = s["error_non_anchor_truth"]
    lines.append(
        f"  solve: {s['points']} points ({s['scan_points']} scans, {s['truth_points']} waypoints) in "
        f"{s['n_groups']} groups ({s['groups']}); rows {s['rows']}; error at non-anchor waypoints mean "
        f"{err.get('mean_m', float('nan')):.2f} m, p90 {err.get('p90_m', float('nan')):.2f} m"
    )
    m = doc["model"]
    lines.append(
        f"  model X = {', '.join(f'{v:.3f}' for v in m['X'])} (RMSE {m['rmse_m']:.2f} m, R² {m['r2']:.3f})"
    )
    r = doc["peak_rss_mb"]
    lines.append(f"  peak RSS: main {r['main']:.0f} MB, largest worker {r['workers']:.0f} MB")
    lines += table_lines(doc["targets"])
    return "\n".join(lines)


def missed_targets(doc: dict[str, Any]) -> list[str]:
    return missed_lines("crowd-scale", doc["targets"])


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scans", type=int, default=DEFAULT_SCANS, help="scans of the fleet (default 100000)")
    p.add_argument("--walks", type=int, default=DEFAULT_WALKS, help="walks of the fleet (default 500)")
    p.add_argument(
        "--scheduler",
        default="local",
        metavar="local|tcp://HOST:PORT",
        help="Dask runs on LocalClusters of 1 and 2 workers, or on this scheduler (default local)",
    )
    p.add_argument(
        "--pair-fraction",
        type=float,
        default=1.0,
        help="fit on an unbiased random subsample of this fraction of the pairs (default 1)",
    )
    p.add_argument(
        "--solve-groups",
        default="chunk:1",
        metavar="floor|all|chunk:K",
        help="walks per solve task (default chunk:1, one walk per task)",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del firmware  # no replay: a synthetic fleet of Walk objects
    doc = run_crowd_scale(
        out,
        n_scans=args.scans,
        n_walks=args.walks,
        scheduler=args.scheduler,
        pair_fraction=args.pair_fraction,
        solve_groups=args.solve_groups,
        seed=seeds[0],
    )
    print(format_table(doc))
    print(f"wrote {out / 'crowd_scale.json'} ({doc['run_s']:.0f} s)")
    return missed_targets(doc)


BENCH = Bench(
    "crowd-scale",
    "the crowd fit and graph solve on a synthetic fleet (100 000 scans / 500 walks) serially and on "
    "Dask 1 and 2 workers (target fit + solve <= 300 s)",
    _run,
    add_arguments=_add_arguments,
    needs_firmware=False,
    in_make_bench=True,
)
