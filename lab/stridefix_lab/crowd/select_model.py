"""Held-out choice of the dissimilarity → distance model per site.

The walks of a site (floor set) are split into K folds BY WALK (sorted by name, walk k → fold k mod K:
deterministic and independent of the argument order). Every candidate of :mod:`.models` is fitted on
the pairs among the walks of K−1 folds and scored on the held-out pairs of fold f: pairs within
fold f and pairs between fold f and the training walks (a new walk is matched against the map as
well as against itself). Pairs are on the same floor with at least one AP in common (the thesis's
pair set, the same for every candidate, so the rows compare).

One streaming pass over the pairs bins each feature per (fold pair {f_i, f_j}, n* stratum); the
training bins of fold f are the sum of the categories without f and its held-out bins the sum of
those with f (exact: sums add), so the pass is shared by all folds and candidates; memory
O(K²·strata·bins). Held-out R² = 1 − Σ_f SSE_f / Σ_f SST_f (SST about each fold's held-out mean),
RMSE = sqrt(Σ SSE / Σ pairs), both at the bin-mean feature; the rank correlation (Spearman ρ of
predicted vs true distance) on a deterministic random subsample of at most ``sample_pairs`` pairs.

The best candidate is the highest held-out R²; with ``score_positions`` (a callable (model fitted on
K−1 folds, held-out walks) → mean position error [m], e.g. the graph solver), the top 3 by R² are
also scored per fold and the lowest mean position error wins. The winner is refitted on all walks.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy.stats import spearmanr
from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd import models as mm
from stridefix_analyzer.crowd.blocks import merge_bins
from stridefix_analyzer.crowd.features import FEATURES, iter_feature_blocks
from stridefix_analyzer.crowd.walks import DEFAULT_BAND, CrowdInputError, Walk, pool_scans

DEFAULT_FOLDS = 5
DEFAULT_SAMPLE_PAIRS = 200_000
TOP_FOR_POSITIONS = 3

ScoreFn = Callable[[mm.FittedModel, list[Walk]], float]


@dataclasses.dataclass
class Selection:
    rows: list[dict]  # one per candidate, sorted by held-out R² (best first)
    best: mm.FittedModel  # the chosen candidate fitted on all walks
    chosen_by: str
    fitted: dict[str, mm.FittedModel]  # every candidate fitted on all walks (for the plot)
    bins: dict[str, list[cm.PairBins]]  # all-walk bins per feature and stratum
    info: dict


def walk_folds(walks: list[Walk], folds: int) -> np.ndarray:
    """Fold of each walk: rank of its name mod ``folds``."""
    order = sorted(range(len(walks)), key=lambda k: (walks[k].name, k))
    out = np.zeros(len(walks), np.int64)
    out[order] = np.arange(len(walks)) % folds
    return out


def parse_candidates(names: Sequence[str | mm.Candidate] | None) -> list[mm.Candidate]:
    """Candidates from names ``form/feature[@n*]`` (or Candidate objects); None = all."""
    if names is None:
        return list(mm.ALL_CANDIDATES)
    by_name = {c.name: c for c in mm.ALL_CANDIDATES}
    out = []
    for n in names:
        if isinstance(n, mm.Candidate):
            out.append(n)
        elif n in by_name:
            out.append(by_name[n])
        else:
            raise CrowdInputError(
                f"candidate {n!r} unknown: use form/feature[@n*], forms {mm.FORMS}, features {tuple(FEATURES)}"
            )
    return out


def _cat_index(folds: int) -> np.ndarray:
    """(K, K) -> id of the unordered fold pair."""
    idx = np.zeros((folds, folds), np.int64)
    k = 0
    for a in range(folds):
        for b in range(a, folds):
            idx[a, b] = idx[b, a] = k
            k += 1
    return idx


def bin_by_fold(
    walks: list[Walk],
    fold_of_walk: np.ndarray,
    folds: int,
    feature_names: tuple[str, ...],
    band: str = DEFAULT_BAND,
    sample_pairs: int = DEFAULT_SAMPLE_PAIRS,
    block: int = cm.DEFAULT_BLOCK,
):
    """One pass over the same-floor pairs: bins[feature][category][stratum] and a pair subsample
    (dict of arrays: features, n_common, d, fold_i, fold_j)."""
    scans = pool_scans(walks, band)
    use = scans.usable & np.isfinite(scans.xy_m[:, 0])
    if use.sum() < 3:
        raise CrowdInputError(f"only {int(use.sum())} scan(s) with truth and an AP in band {band}")
    R, xy, floor = scans.R[use], scans.xy_m[use], scans.floor[use]
    fold = fold_of_walk[scans.walk[use]]
    cat_of = _cat_index(folds)
    n_cat, n_str = int(cat_of.max()) + 1, len(mm.STRATA_EDGES)
    bins = {
        f: [[cm.PairBins(width=FEATURES[f][1]) for _ in range(n_str)] for _ in range(n_cat)]
        for f in feature_names
    }
    groups = np.unique(floor)
    total = sum(int(np.sum(floor == g)) * (int(np.sum(floor == g)) - 1) // 2 for g in groups)
    rate = min(1.0, sample_pairs / max(total, 1))
    rng = np.random.default_rng(0)
    samples: list[dict] = []
    for g in groups:
        sel = np.flatnonzero(floor == g)
        Rg = R[sel][:, np.isfinite(R[sel]).any(axis=0)]
        P, F = xy[sel], fold[sel]
        for i0, j0, feats, nc, keep in iter_feature_blocks(Rg, feature_names, block):
            bi, bj = keep.shape
            d = np.hypot(
                np.subtract.outer(P[i0 : i0 + bi, 0], P[j0 : j0 + bj, 0]),
                np.subtract.outer(P[i0 : i0 + bi, 1], P[j0 : j0 + bj, 1]),
            )[keep]
            fi = np.broadcast_to(F[i0 : i0 + bi, None], keep.shape)[keep]
            fj = np.broadcast_to(F[None, j0 : j0 + bj], keep.shape)[keep]
            n = nc[keep]
            key = cat_of[fi, fj] * n_str + mm.stratum_of(n, mm.STRATA_EDGES)
            vals = {f: feats[f][keep] for f in feature_names}
            for k in np.unique(key):
                m = key == k
                dk = d[m]
                for f in feature_names:
                    bins[f][k // n_str][k % n_str].add(vals[f][m], dk)
            take = rng.random(d.size) < rate
            samples.append(
                {"d": d[take], "n_common": n[take], "fold_i": fi[take], "fold_j": fj[take]}
                | {f: vals[f][take] for f in feature_names}
            )
    sample = {k: np.concatenate([s[k] for s in samples]) for k in samples[0]} if samples else {}
    info = {
        "scans": int(use.sum()),
        "pairs": int(sum(b.n_pairs for c in bins[feature_names[0]] for b in c)),
        "pairs_same_floor": int(total),
        "floors": sorted(int(v) for v in groups),
        "sample_pairs": int(len(sample.get("d", ()))),
    }
    return bins, sample, info


def _merge(bins_f, cats: list[int], width: float) -> list[cm.PairBins]:
    n_str = len(bins_f[0])
    return [merge_bins([bins_f[c][s] for c in cats], width_db=width) for s in range(n_str)]


def _spearman(x: np.ndarray, y: np.ndarray) -> float:
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3 or np.ptp(x[ok]) == 0:
        return math.nan
    return float(spearmanr(x[ok], y[ok])[0])


def score_candidates(bins, sample: dict, K: int, cands: list[mm.Candidate], say: Callable[[str], None]):
    """Held-out scores of ``cands`` from :func:`bin_by_fold`'s bins and sample (module docstring).

    Returns (rows sorted by held-out R², best first; candidates fitted on all pairs; per candidate
    its K fold models (None where the fit failed); all-pair bins per feature)."""
    names = tuple(dict.fromkeys(c.feature for c in cands))
    cat_of = _cat_index(K)
    n_cat = int(cat_of.max()) + 1
    fold_models: dict[str, list[mm.FittedModel | None]] = {c.name: [] for c in cands}
    acc: dict[str, dict[str, Any]] = {
        c.name: {"sse": 0.0, "sst": 0.0, "n": 0.0, "fold_r2": [], "rho": [], "rho_n": []} for c in cands
    }
    for f in range(K):
        with_f = sorted(set(cat_of[f].tolist()))
        without = [c for c in range(n_cat) if c not in with_f]
        held = (sample["fold_i"] == f) | (sample["fold_j"] == f) if sample else None
        for feat in names:
            w = FEATURES[feat][1]
            tr, ho = _merge(bins[feat], without, w), _merge(bins[feat], with_f, w)
            sst, N = mm.bin_sst(merge_bins(ho, width_db=w))
            for c in (c for c in cands if c.feature == feat):
                a = acc[c.name]
                try:
                    m = mm.fit_candidate(c, tr)
                except ValueError:
                    fold_models[c.name].append(None)
                    continue
                fold_models[c.name].append(m)
                sse = mm.heldout_sse(m, ho)
                a["sse"] += sse
                a["sst"] += sst
                a["n"] += N
                a["fold_r2"].append(1.0 - sse / sst if sst > 0 else math.nan)
                if held is not None and held.any():
                    g, _ = m.predict_feature(sample[feat][held], sample["n_common"][held])
                    a["rho"].append(_spearman(g, sample["d"][held]))
                    a["rho_n"].append(int(held.sum()))
        say(f"fold {f + 1}/{K} done")
    fitted, rows = {}, []
    all_bins = {feat: _merge(bins[feat], list(range(n_cat)), FEATURES[feat][1]) for feat in names}
    for c in cands:
        a = acc[c.name]
        row = {
            "name": c.name,
            "feature": c.feature,
            "form": c.form,
            "stratified": c.stratified,
            "reference": c == mm.REFERENCE,
            "heldout_r2": 1.0 - a["sse"] / a["sst"] if a["sst"] > 0 else math.nan,
            "heldout_rmse_m": math.sqrt(a["sse"] / a["n"]) if a["n"] else math.nan,
            "heldout_spearman": float(np.average(np.nan_to_num(a["rho"]), weights=a["rho_n"]))
            if a["rho_n"]
            else math.nan,
            "fold_r2": a["fold_r2"],
            "heldout_pairs": int(a["n"]),
            "folds_fitted": sum(m is not None for m in fold_models[c.name]),
        }
        try:
            fitted[c.name] = mm.fit_candidate(c, all_bins[c.feature])
            row["all_walks_r2"] = fitted[c.name].fit["r2"]
        except ValueError as exc:
            row["error"] = str(exc)
        rows.append(row)
    rows.sort(key=lambda r: -r["heldout_r2"] if math.isfinite(r["heldout_r2"]) else math.inf)
    return rows, fitted, fold_models, all_bins


def select_model(
    walks: list[Walk],
    candidates: Sequence[str | mm.Candidate] | None = None,
    folds: int = DEFAULT_FOLDS,
    band: str = DEFAULT_BAND,
    score_positions: ScoreFn | None = None,
    progress: Callable[[str], None] | None = None,
    sample_pairs: int = DEFAULT_SAMPLE_PAIRS,
) -> Selection:
    """Fit every candidate on K−1 folds, score it on the held-out pairs, choose (module docstring)."""
    cands = parse_candidates(candidates)
    if len(walks) < 2:
        raise CrowdInputError(f"held-out selection needs at least 2 walks, got {len(walks)}")
    K = max(2, min(int(folds), len(walks)))
    say = progress or (lambda s: None)
    fw = walk_folds(walks, K)
    names = tuple(dict.fromkeys(c.feature for c in cands))
    bins, sample, info = bin_by_fold(walks, fw, K, names, band, sample_pairs)
    say(f"binned {info['pairs']} pairs of {info['scans']} scans, {K} folds")
    rows, fitted, fold_models, all_bins = score_candidates(bins, sample, K, cands, say)
    ok = [r for r in rows if r["name"] in fitted and math.isfinite(r["heldout_r2"])]
    if not ok:
        raise CrowdInputError("no candidate could be fitted and scored on held-out walks")
    best_row, chosen_by = ok[0], "held-out R²"
    if score_positions is not None:
        for r in ok[:TOP_FOR_POSITIONS]:
            errs = []
            for f in range(K):
                fm = fold_models[r["name"]][f]
                held_walks = [w for w, k in zip(walks, fw, strict=True) if k == f]
                if fm is not None and held_walks:
                    errs.append(float(score_positions(fm, held_walks)))
            r["heldout_position_error_m"] = float(np.mean(errs)) if errs else math.nan
            say(f"positions {r['name']}: {r['heldout_position_error_m']:.2f} m")
        scored = [r for r in ok[:TOP_FOR_POSITIONS] if math.isfinite(r["heldout_position_error_m"])]
        if scored:
            best_row = min(scored, key=lambda r: r["heldout_position_error_m"])
            chosen_by = f"held-out solved position error among the top {TOP_FOR_POSITIONS} by held-out R²"
    info.update(
        folds=K,
        walks=len(walks),
        band=band,
        fold_of_walk={w.name: int(k) for w, k in zip(walks, fw, strict=True)},
    )
    return Selection(rows, fitted[best_row["name"]], chosen_by, fitted, all_bins, info)


# --- `stridefix-lab crowd models` ------------------------------------------------------------------


def format_table(sel: Selection) -> str:
    """The candidates side by side (best first), the reference row marked."""
    pos = any("heldout_position_error_m" in r for r in sel.rows)
    head = f"{'candidate':30s} {'R² held-out':>11s} {'RMSE m':>7s} {'ρ':>6s} {'R² all':>7s}"
    lines = [head + ("  pos. err m" if pos else "")]
    for r in sel.rows:
        line = (
            f"{r['name'] + (' (ref)' if r['reference'] else ''):30s} {r['heldout_r2']:11.3f} "
            f"{r['heldout_rmse_m']:7.2f} {r['heldout_spearman']:6.3f} {r.get('all_walks_r2', math.nan):7.3f}"
        )
        if pos and "heldout_position_error_m" in r:
            line += f"  {r['heldout_position_error_m']:10.2f}"
        lines.append(line)
    i = sel.info
    lines.append(
        f"best: {sel.best.name} (chosen by {sel.chosen_by}); {i['walks']} walks in {i['folds']} folds by walk, "
        f"{i['pairs']} same-floor pairs with ≥ 1 common AP of {i['scans']} scans (band {i['band']}); "
        f"ρ on {i['sample_pairs']} sampled pairs"
    )
    return "\n".join(lines)


def run_models(args) -> dict:
    import json
    import os

    from stridefix_analyzer.crowd.plots import plot_models
    from stridefix_analyzer.crowd.walks import load_walks

    walks = load_walks(args.logs)
    sel = select_model(walks, args.candidates, args.folds, args.band, progress=None)
    os.makedirs(args.out, exist_ok=True)
    doc = {
        "reference": mm.REFERENCE.name,
        "chosen_by": sel.chosen_by,
        "best": sel.best.to_json(),
        "rows": sel.rows,
        "info": sel.info,
        "inputs": [w.name for w in walks],
    }
    path = os.path.join(args.out, "models.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=2, default=float)
        f.write("\n")
    png = os.path.join(args.out, "models.png")
    plot_models(sel, png)
    print(format_table(sel))
    print(f"wrote {path} and {png}")
    return doc
