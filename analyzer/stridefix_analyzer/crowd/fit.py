"""``stridefix crowd fit``: the dissimilarity → distance model g(d) = max(X1, X2 + X3·d) from walks.

Every scan pair on a floor (positions interpolated on the truth), exact streaming binning, bounded
least squares on the bins (:mod:`.model`) → ``model.json`` + ``model_fit.png``. The block pairs run
as tasks (:mod:`.blocks`) serially, on a local Dask cluster (``--scheduler local --workers N``) or on a
scheduler's workers (``--scheduler tcp://…``), with bit-identical bins; ``--pair-fraction`` < 1 fits on an
unbiased random subsample of the scan pairs (stated in the method text and the JSON).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from typing import Any

import numpy as np

from stridefix_analyzer.crowd import blocks as cbk
from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd.walks import DEFAULT_BAND, CrowdInputError, Walk, load_walks, pool_scans
from stridefix_analyzer.parallel import SchedulerError, check_scheduler

PRECISIONS = ("float64", "float32")


def fit_walks(
    walks: list[Walk],
    mode: str = cm.DEFAULT_MODE,
    band: str = DEFAULT_BAND,
    width_db: float = cm.DEFAULT_BIN_WIDTH_DB,
    min_common: int = 1,
    *,
    scheduler: str | None = None,
    workers: int = 2,
    pair_fraction: float = 1.0,
    precision: str = "float64",
    seed: int = 0,
    client: Any = None,
) -> tuple[cm.DistanceModel, cm.PairBins]:
    """Fit g on every pair (or an unbiased ``pair_fraction`` sample of the pairs) of placed scans on the
    same floor of ``walks`` (streaming binning; the block pairs on ``scheduler``, see :mod:`.blocks`)."""
    t0 = time.perf_counter()
    if precision not in PRECISIONS:
        raise CrowdInputError(f"precision {precision!r} not one of {PRECISIONS}")
    try:
        scheduler = check_scheduler(scheduler)
    except SchedulerError as exc:
        raise CrowdInputError(str(exc)) from exc
    if not 0 < pair_fraction <= 1:
        raise CrowdInputError(f"--pair-fraction {pair_fraction}: must be in (0, 1]")
    scans = pool_scans(walks, band)
    use = scans.usable & np.isfinite(scans.xy_m[:, 0])
    if use.sum() < 3:
        raise CrowdInputError(
            f"only {int(use.sum())} scan(s) with truth and an AP in band {band}: nothing to fit"
        )
    settings = cbk.BinSettings(mode=mode, width_db=width_db, min_common=min_common)
    t_bin = time.perf_counter()
    bins, binning = cbk.bin_pairs_tasks(
        scans.R[use],
        scans.xy_m[use],
        scans.floor[use],
        settings,
        dtype=np.dtype(precision),
        scheduler=scheduler,
        workers=workers,
        pair_fraction=pair_fraction,
        seed=seed,
        client=client,
    )
    binning["bin_s"] = time.perf_counter() - t_bin
    binning["scheduler"] = "client" if client is not None else (scheduler or "serial")
    binning["workers"] = workers if scheduler == "local" else None
    model = cm.fit_binned(bins, mode)
    if "sampling" in binning:
        model.method += f"; {binning['sampling']}"
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
        binning=binning,
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


def run_fit(args: argparse.Namespace) -> dict[str, Any]:
    walks = load_walks(args.logs)
    model, bins = fit_walks(
        walks,
        args.dissimilarity,
        args.band,
        args.bin_width_db,
        args.min_common_aps,
        scheduler=args.scheduler,
        workers=args.workers,
        pair_fraction=args.pair_fraction,
        precision=args.precision,
    )
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
