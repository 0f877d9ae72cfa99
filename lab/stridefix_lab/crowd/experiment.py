"""``stridefix-lab crowd experiment``: Kannan's results table in SIL and on real msindoor walks.

``--sil``: crowd walkers = ``stridefix sim --scenario pace_normal`` (two laps of the office loop) with
different seeds (different people), each replayed through ``stridefixd`` (for ``STEP``) with its
truth. The model g(d) and the stride scale are fitted on separate walkers (``--fit-seeds``), never on
the scored walks. Anchors: every 4th scan point of each walk; error at the other scan points. Then
the radio map from the crowd: a site built from the solved positions of the scored walks and one built
from their truth; every scored walk (and a held-out walk) is replayed with each site and scored
``wifi_only`` by ``stridefix analyze``.

``--msindoor DIR`` (a floor folder, or the msindoor root for every floor): each trace is imported
(``stridefix_analyzer.datasets.msindoor``, cached) and replayed through ``stridefixd`` once per
heading variant (``firmware.HEADING_VARIANTS``); the walks used are those of the variant the fitting
traces agree on at their anchors (:func:`.graph.agreed_variant`: the smallest spread of per-walk
heading bias, the truth between anchors never read). The first
``--limit`` traces (sorted by name) are scored; the model and stride scale come from the floor's other
traces. Anchors: every 4th waypoint (``--anchors``); error at the other waypoints. The floor's model is also fitted
on all its traces and reported.

Stride scale: Σ‖truth_{k+1} − truth_k‖ / Σ‖DR_{k+1} − DR_k‖ over consecutive truth points of the
fitting walks (the firmware's default Weinberg K is not the crowd's).
"""

from __future__ import annotations

import concurrent.futures
import json
import os
import time
from pathlib import Path

from stridefix_analyzer import console
from stridefix_analyzer.crowd.fit import fit_walks, format_model
from stridefix_analyzer.crowd.sites import build_crowd_sites
from stridefix_analyzer.crowd.walks import CrowdInputError, load_walks
from stridefix_analyzer.firmware import Firmware, add_stridefixd_argument
from stridefix_analyzer.parallel import add_jobs_argument
from stridefix_analyzer.scoring.targets import missed_lines, table_lines

from stridefix_lab.crowd.experiment_msindoor import run_msindoor
from stridefix_lab.crowd.experiment_table import format_table, run_table, stride_scale
from stridefix_lab.crowd.experiment_targets import solve_targets
from stridefix_lab.stages import replay, simulate

DEFAULT_OUT = os.path.join("out", "crowd", "experiment")

# --- SIL ---------------------------------------------------------------------------------------------


def _sil_walk(scenario: str, seed: int, firmware: Firmware, out: Path, duration_s: float | None) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    summary = simulate(
        scenario, seed, out, f"sim {scenario} seed {seed}", CrowdInputError, duration_s or None
    )
    replay(
        firmware,
        f"stridefixd seed {seed}",
        CrowdInputError,
        input=out / "board.candump",
        log=out / "stridefixd.lcmlog",
        sets=[f"heading.map_rotation_deg={summary.get('map_rotation_deg', 0.0)}"],
        extra=["--config", str(out / "init_truth.ini")],
    )
    return {
        "seed": seed,
        "dir": out,
        "summary": summary,
        "spec": f"{out / 'stridefixd.lcmlog'},{out / 'truth.lcmlog'}",
    }


def _replay_score(walk: dict, site: Path, firmware: Firmware, out: Path) -> dict:
    from stridefix_analyzer.scoring.analyze import run_analyze

    out.mkdir(parents=True, exist_ok=True)
    log = out / "stridefixd.lcmlog"
    replay(
        firmware,
        f"stridefixd --site {site}",
        CrowdInputError,
        input=walk["dir"] / "board.candump",
        log=log,
        site=site,
        fusion="wifi_only",
    )
    summary, _ = run_analyze(
        [str(log), str(walk["dir"] / "truth.lcmlog")],
        str(out),
        scheme="wifi_only",
        label=f"seed {walk['seed']} wifi_only, {site.name}",
    )
    pe = summary.get("position_error_m") or summary.get("metrics", {}).get("position_error_m", {})
    return {"mean_m": pe.get("mean"), "p90_m": pe.get("p90"), "n": pe.get("n")}


def run_sil(args, progress) -> dict:
    t0 = time.perf_counter()
    firmware = Firmware(args.stridefixd)
    out = Path(args.out) / "sil"
    seeds = [int(s) for s in args.seeds.split(",") if s]
    fit_seeds = [int(s) for s in args.fit_seeds.split(",") if s]
    heldout = [int(s) for s in args.heldout_seeds.split(",") if s]
    jobs = [(s, "fit") for s in fit_seeds] + [(s, "walk") for s in seeds] + [(s, "heldout") for s in heldout]
    progress(
        f"crowd experiment --sil: simulating {len(jobs)} walkers ({args.scenario}) and "
        f"replaying them through stridefixd"
    )
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futs = {
            (s, kind): pool.submit(
                _sil_walk, args.scenario, s, firmware, out / f"{kind}-s{s}", args.duration_s
            )
            for s, kind in jobs
        }
        runs = {k: f.result() for k, f in futs.items()}
    sim_s = time.perf_counter() - t0
    fit_w = load_walks([runs[(s, "fit")]["spec"] for s in fit_seeds])
    walks = load_walks([runs[(s, "walk")]["spec"] for s in seeds])
    model, _ = fit_walks(fit_w, mode=args.dissimilarity, band=args.band, min_common=args.min_common_aps)
    scale = stride_scale(fit_w)
    progress("model (fit walkers " + ",".join(map(str, fit_seeds)) + "): " + format_model(model))
    progress(f"stride scale {scale:.4f}; table on {len(walks)} walkers, anchors {args.anchors}")
    rows, positions = run_table(walks, model, args.anchors, args.solver, args.band, scale, progress)
    # radio map from the crowd vs from the truth, scored wifi_only
    best = min((r for r in rows if r["key"] in ("hybrid_w", "both_w")), key=lambda r: r["mean_m"])
    xy, points, _ = positions[best["key"]]
    rot = runs[(seeds[0], "walk")]["summary"].get("map_rotation_deg", 0.0)
    sites = build_crowd_sites(
        walks, xy, points, str(out / "crowd.sfsite"), str(out / "truth.sfsite"), map_rotation_deg=rot
    )
    fixes = []
    for kind, ss in (("walk", seeds), ("heldout", heldout)):
        for s in ss:
            row = {"seed": s, "kind": kind}
            for label in ("truth", "crowd"):
                row[label] = _replay_score(
                    runs[(s, kind)],
                    Path(sites[label]["path"]),
                    firmware,
                    out / "replay" / f"{kind}-s{s}-{label}",
                )
            fixes.append(row)
    doc = {
        "experiment": "sil",
        "scenario": args.scenario,
        "seeds": seeds,
        "fit_seeds": fit_seeds,
        "heldout_seeds": heldout,
        "model": model.to_json(),
        "stride_scale": scale,
        "rows": rows,
        "radiomap": {"positions_from": best["key"], "sites": sites, "wifi_only": fixes},
        "sim_s": sim_s,
        "run_s": time.perf_counter() - t0,
    }
    return doc


def format_fixes(fixes: list[dict]) -> str:
    lines = [f"{'walk':<14}{'truth-map wifi_only mean':>26}{'crowd-map wifi_only mean':>26}"]
    for r in fixes:
        t, c = r["truth"]["mean_m"], r["crowd"]["mean_m"]
        lines.append(f"{r['kind'] + ' s' + str(r['seed']):<14}{t:>24.2f} m{c:>24.2f} m")
    return "\n".join(lines)


# --- command line ------------------------------------------------------------------------------------


def add_arguments(p) -> None:
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--sil", action="store_true", help="SIL: several simulated walkers")
    g.add_argument("--msindoor", metavar="DIR", help="msindoor floor folder (or the root)")
    p.add_argument(
        "--out", default=DEFAULT_OUT, metavar="DIR", help=f"outputs and caches (default {DEFAULT_OUT})"
    )
    add_stridefixd_argument(p)
    p.add_argument("--scenario", default="pace_normal", help="SIL scenario (default pace_normal)")
    p.add_argument("--seeds", default="1,2,3,4,5,6", help="SIL scored walkers (default 1..6)")
    p.add_argument("--fit-seeds", default="101,102", help="SIL model-fitting walkers")
    p.add_argument("--heldout-seeds", default="201", help="SIL walkers only replayed on the maps")
    p.add_argument("--duration-s", type=float, default=None, help="SIL: cut each walk (s)")
    p.add_argument(
        "--anchors",
        default="every:4",
        metavar="every:K",
        help="known truth points per walk: every K-th scan point (SIL) or waypoint (msindoor) (default every:4, the thesis)",
    )
    p.add_argument(
        "--limit",
        type=int,
        default=20,
        help="msindoor: score the first N traces per floor, fit on the rest (default 20;"
        " 0 = score all, fit on all)",
    )
    p.add_argument(
        "--band", choices=("2.4", "all"), default="2.4", help="APs used (default 2.4 GHz only, the thesis)"
    )
    p.add_argument(
        "--dissimilarity",
        choices=("common_sum", "common_scaled"),
        default="common_sum",
        help="dissimilarity (default common_sum, the thesis)",
    )
    p.add_argument(
        "--min-common-aps",
        type=int,
        default=1,
        help="exclude pairs sharing fewer APs (default 1, the thesis)",
    )
    p.add_argument("--solver", choices=("auto", "native", "scipy"), default="auto")
    p.add_argument(
        "--check-targets",
        action="store_true",
        help="msindoor: exit 1 when a floor misses its target (graph ≥ 20 %% better than anchor interpolation)",
    )
    add_jobs_argument(p, "parallel sim/replay jobs")


def run_experiment(args) -> int:
    def progress(msg):
        console.say(msg)

    Path(args.out).mkdir(parents=True, exist_ok=True)
    status = 0
    if args.sil:
        doc = run_sil(args, progress)
        m = doc["model"]
        print(
            f"SIL model ({m['mode']}, band {args.band}; fitted on walkers {args.fit_seeds}): "
            f"X1 {m['floor_m']:.3f} m, X2 {m['intercept_m']:.3f} m, X3 {m['slope_m_per_db']:.4f} "
            f"m/dB, RMSE {m['rmse_m']:.2f} m, R² {m['r2']:.3f}, {m['n_pairs']} pairs; stride "
            f"scale {doc['stride_scale']:.3f}"
        )
        print(
            f"SIL: {len(doc['seeds'])} walkers of {doc['scenario']}, anchors {args.anchors} scan "
            f"point, error at the other scan points; solver {doc['rows'][0]['solver']}"
        )
        print(format_table(doc["rows"]))
        print(
            f"radio map from crowd positions ({doc['radiomap']['positions_from']}) vs truth, "
            f"wifi_only fixes replayed through stridefixd:"
        )
        print(format_fixes(doc["radiomap"]["wifi_only"]))
        path = Path(args.out) / "sil.json"
    else:
        doc = run_msindoor(args, progress)
        for f in doc["floors"]:
            m = f["model_all_traces"]
            print(
                f"{f['floor']}: model on all {f['traces']} traces X1 {m['floor_m']:.3f} m, "
                f"X2 {m['intercept_m']:.3f} m, X3 {m['slope_m_per_db']:.4f} m/dB, RMSE "
                f"{m['rmse_m']:.2f} m, R² {m['r2']:.3f}, {m['n_pairs']} pairs"
            )
            print(
                f"{f['floor']}: {len(f['scored_walks'])} walks, anchors {args.anchors} waypoints, "
                f"error at the other waypoints; solver {f['rows'][0]['solver']}"
            )
            print(format_table(f["rows"]))
        doc["targets"] = solve_targets(doc["floors"])
        print("\n".join(table_lines(doc["targets"])))
        for line in missed_lines("crowd experiment", doc["targets"]):
            print(f"TARGET MISSED {line}")
        status = 1 if args.check_targets and not all(t["met"] for t in doc["targets"]) else 0
        path = Path(args.out) / "msindoor.json"
    path.write_text(
        json.dumps(doc, indent=2, default=lambda o: str(o) if isinstance(o, Path) else float(o)) + "\n"
    )
    print(f"wrote {path} ({doc['run_s']:.0f} s)")
    return status
