"""``crowd experiment --msindoor``: the thesis table on real msindoor walks (see :mod:`.experiment`)."""

from __future__ import annotations

import concurrent.futures
import dataclasses
import math
import time
from pathlib import Path

from stridefix_analyzer.crowd.fit import fit_walks, format_model
from stridefix_analyzer.crowd.graph import agreed_variant
from stridefix_analyzer.crowd.graph_run import anchor_similarities
from stridefix_analyzer.crowd.models import ThesisAdapter
from stridefix_analyzer.crowd.walks import CrowdInputError, load_walks
from stridefix_analyzer.firmware import HEADING_VARIANTS, Firmware

from stridefix_lab.crowd.experiment_graph import select_pair_model
from stridefix_lab.crowd.experiment_table import run_table, stride_scale
from stridefix_lab.stages import replay


def _ms_walk(trace: Path, cache: Path, firmware: Firmware) -> dict:
    """Import one trace and replay it once per heading variant (cached); its walk specs per variant."""
    import warnings

    from stridefix_analyzer import datasets

    log = cache / f"{trace.stem}.lcmlog"
    fresh = log.is_file() and log.stat().st_mtime >= trace.stat().st_mtime
    if not fresh:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            datasets.get("msindoor").import_walk(trace, log)
    specs = {}
    for k, (variant, sets) in enumerate(HEADING_VARIANTS.items()):
        fw = cache / f"{trace.stem}.fw{k}.lcmlog"
        if not (fresh and fw.is_file() and fw.stat().st_mtime >= log.stat().st_mtime):
            replay(
                firmware,
                f"stridefixd {trace.name} ({variant})",
                CrowdInputError,
                input=f"lcmlog:{log}",
                log=fw,
                sets=[*datasets.get("msindoor").firmware_sets, *sets],
            )
        specs[variant] = (str(fw), str(log))
    return {"trace": trace.name, "specs": specs}


def _agreed_walks(prepared: list[dict], n_fit_from: int, anchors: str):
    """The walks of the heading variant the fitting walks (``prepared[n_fit_from:]``) agree on at
    their anchors (:func:`.graph.agreed_variant`), the variant and its fleet priors."""
    by_variant = {}
    for variant in HEADING_VARIANTS:
        walks = load_walks([p["specs"][variant] for p in prepared])
        for w, p in zip(walks, prepared):
            w.name = p["trace"]
        by_variant[variant] = walks
    sims = {
        v: [s for s in anchor_similarities(ws[n_fit_from:], anchors) if s is not None]
        for v, ws in by_variant.items()
    }
    variant, priors = agreed_variant(sims)
    return by_variant[variant], variant, priors


def _floors(root: Path) -> list[Path]:
    if (root / "path_data_files").is_dir():
        return [root]
    floors = sorted(p.parent for p in root.glob("*/*/path_data_files"))
    if not floors:
        raise CrowdInputError(f"{root}: no <floor>/path_data_files or */*/path_data_files folder")
    return floors


def _usable(walks, min_truth: int = 3):
    """Walks that can be scored: steps, ≥ ``min_truth`` waypoints, ≥ 1 scan."""
    return [w for w in walks if len(w.step_t_us) and len(w.truth_t_us) >= min_truth and w.n_scans]


def run_msindoor(args, progress) -> dict:
    t0 = time.perf_counter()
    firmware = Firmware(args.stridefixd)
    docs = []
    for floor in _floors(Path(args.msindoor)):
        label = f"{floor.parent.name}/{floor.name}"
        traces = sorted((floor / "path_data_files").glob("*.txt"))
        cache = Path(args.out) / "msindoor" / f"{floor.parent.name}-{floor.name}"
        cache.mkdir(parents=True, exist_ok=True)
        progress(f"crowd experiment --msindoor {label}: importing and replaying {len(traces)} traces")
        t1 = time.perf_counter()
        with concurrent.futures.ProcessPoolExecutor(max_workers=args.jobs) as pool:
            prepared = list(pool.map(_ms_walk, traces, [cache] * len(traces), [firmware] * len(traces)))
        prep_s = time.perf_counter() - t1
        fit_from = args.limit if args.limit and args.limit < len(prepared) else 0
        all_walks, variant, priors = _agreed_walks(prepared, fit_from, args.anchors)
        progress(
            f"{label} heading variant the fitting walks agree on at their anchors: {variant} (heading "
            f"bias spread {math.degrees(priors.heading_sigma_rad):.1f} deg over {priors.walks_used} walks)"
        )
        scored = _usable(all_walks[: args.limit]) if args.limit else _usable(all_walks)
        fitting = all_walks[args.limit :] if args.limit and args.limit < len(all_walks) else all_walks
        model_all, _ = fit_walks(
            all_walks, mode=args.dissimilarity, band=args.band, min_common=args.min_common_aps
        )
        model, _ = fit_walks(fitting, mode=args.dissimilarity, band=args.band, min_common=args.min_common_aps)
        scale = stride_scale(_usable(fitting, 2))
        progress(f"{label} model on all {len(all_walks)} traces: " + format_model(model_all))
        progress(
            f"{label} model on the {len(fitting)} non-scored traces: X = "
            f"{[round(v, 4) for v in model.params]}; stride scale {scale:.3f}; "
            f"table on {len(scored)} walks"
        )
        sel = select_pair_model(fitting, args.anchors, args.solver, args.band, progress)
        wifi_models = [(sel.best.name, sel.best), ("thesis/common_sum, reference", ThesisAdapter(model))]
        rows, _ = run_table(scored, model, args.anchors, args.solver, args.band, scale, progress, wifi_models)
        docs.append(
            {
                "floor": label,
                "traces": len(traces),
                "scored_walks": [w.name for w in scored],
                "fit_traces": len(fitting),
                "model_all_traces": model_all.to_json(),
                "model_used": model.to_json(),
                "pair_models": {"chosen": sel.best.name, "chosen_by": sel.chosen_by, "rows": sel.rows},
                "stride_scale": scale,
                "heading_variant": {
                    "chosen": variant,
                    "by": "smallest heading-bias spread at the fitting walks' anchors",
                    "priors": dataclasses.asdict(priors),
                },
                "rows": rows,
                "prepare_s": prep_s,
            }
        )
    return {"experiment": "msindoor", "floors": docs, "run_s": time.perf_counter() - t0}
