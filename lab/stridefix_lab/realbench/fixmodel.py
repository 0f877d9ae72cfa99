"""The site's Wi-Fi fix-error model for the ``ekf`` scheme, measured on training walks the map never saw.

The matcher's ``accuracy_m`` is the spread of its neighbours, a shape rather than a calibrated σ
(fixes whose real error is 5–6 m report 1.5–3 m). The ``ekf`` scheme takes its R as
``accuracy_m² · M`` (``firmware/core/sf_ekf.h``); this module measures M against the truth:

* the walks of a group are dealt into blocks and replayed with ``--fusion wifi_only`` on maps without
  their own block and the held-out block (:func:`.select.block_replays`, the same machinery as the
  matcher's inner cross-validation, with that block's matcher settings), so every residual is out of
  sample and none comes from the walk being scored;
* per held-out block a, one fix's error covariance F + accuracy²·M (e = fix − truth, pooled over the
  other blocks' walks): a least-squares fit of the per-axis squared error on accuracy², since the error
  follows the matcher's accuracy only weakly (site1/F2: 3.8 m rms per axis at 2 m, 5.3 m at 6 m), and
  the axes' shape from the mean e·eᵀ (a corridor's error runs along it). The law is fitted on the raw
  errors: the worst fixes come with the matcher's worst accuracies (70 m off at 30 m), and that tail
  is what the gate needs (winsorised, site2/F3 lost a truth-initialised walk to 47 m: the law said
  such a fix was better than the matcher did). The shape and the correlation use |e| winsorised at its
  :data:`WINSOR_QUANTILE` quantile, so a few fixes outside the training walks' coverage cannot set them;
* consecutive fixes err alike (neighbouring scans match the same wrong reference points; a standing
  walker gets the same wrong fix again), and a filter that takes them as independent follows them. The
  scheme carries that part of the error as a state c (a Gauss–Markov process in the distance walked);
  its share a of a fix's error and correlation length ℓ come from the correlation of two fixes' errors
  (in metres, per axis) against the distance walked between them along the truth,
  r(Δd) = a·exp(−Δd/ℓ) (:func:`correlation`); σ_c² = a times one fix's variance at the median
  accuracy, and every fix keeps at least the white share 1 − a of its own variance.

The result goes into the fold's site file (``site_t.has_fix_model``, ``fix_floor_cov_m2``,
``fix_cov_per_acc2`` — the scheme's prior, which it can only raise online — ``fix_bias_sigma_m``, ``fix_bias_length_m``,
``fix_white_share``): the map carries its own error model. A user's ``--set`` of an ``ekf.fix_*`` key
(:data:`KEYS`) skips the measurement, and the parameters hold.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from stridefix_analyzer.console import Progress
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.parallel import TaskRunner

from stridefix_lab.realbench import select as rs

#: fewest walks in a group to measure the model (fewer: the firmware prior). Fewer than the inner
#: cross-validation needs to choose (6): the inner maps then hold fewer walks than the fold's (2 of 3 on
#: gsd's four trials) and the errors they give run high, but a conservative model beats the matcher's
#: word, which is the optimistic one (1.5–3 m accuracies for 5–6 m errors)
MIN_WALKS = 3
#: fewest fixes per block for a model (fewer: the firmware prior for that block)
MIN_FIXES = 20
#: the per-accuracy² part is kept at least this (the firmware's model needs it positive definite)
MIN_PER_ACC2 = 0.01
#: |e| above this quantile is pulled onto it
WINSOR_QUANTILE = 0.9
#: pairs of fixes at most this many fixes apart enter the correlation
MAX_LAG = 20
#: bins of the distance walked between two fixes [m] for the correlation's decay
DISTANCE_BINS_M = (0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0)
#: fewest pairs in a bin for it to count
MIN_PAIRS = 10
#: the correlation length is kept in this range [m]
LENGTH_RANGE_M = (1.0, 200.0)
#: the correlated share a is kept at most this, so every fix keeps a white part
MAX_CORRELATED_SHARE = 0.9
KEYS = (
    "ekf.fix_var_x_per_acc2",
    "ekf.fix_var_y_per_acc2",
    "ekf.fix_cov_xy_per_acc2",
    "ekf.fix_floor_xx_m2",
    "ekf.fix_floor_yy_m2",
    "ekf.fix_floor_xy_m2",
    "ekf.fix_bias_sigma_m",
    "ekf.fix_bias_length_m",
    "ekf.fix_white_share",
)


def _winsorise(v: np.ndarray) -> np.ndarray:
    radius = np.hypot(v[:, 0], v[:, 1])
    cap = float(np.quantile(radius, WINSOR_QUANTILE))
    return v * np.minimum(1.0, cap / np.maximum(radius, 1e-12))[:, None]


def correlation(rows: Sequence[np.ndarray]) -> tuple[float, float, list[dict[str, float]]]:
    """a and ℓ [m] of r(Δd) = a·exp(−Δd/ℓ), the correlation of two fixes' errors (per axis, in metres)
    against the distance walked between them (pairs within a walk, 1..:data:`MAX_LAG` fixes apart,
    binned by :data:`DISTANCE_BINS_M`, a log-linear fit weighted by the pairs per bin), r = covariance /
    variance of the same errors; and the bins. a = 0 when no bin has a positive correlation."""
    allq = np.concatenate([0.5 * np.sum(r[:, :2] ** 2, axis=1) for r in rows]) if rows else np.zeros(0)
    variance = float(allq.mean()) if len(allq) else 0.0
    prods: list[np.ndarray] = []
    dists: list[np.ndarray] = []
    for r in rows:
        e = r[:, :2]
        for k in range(1, min(MAX_LAG, len(r) - 1) + 1):
            prods.append(0.5 * np.sum(e[k:] * e[:-k], axis=1))
            dists.append(np.abs(r[k:, 3] - r[:-k, 3]))
    if not prods or variance <= 0:
        return 0.0, LENGTH_RANGE_M[0], []
    q, d = np.concatenate(prods) / variance, np.concatenate(dists)
    bins = []
    edges = (*DISTANCE_BINS_M, np.inf)
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        m = (d >= lo) & (d < hi)
        if m.sum() >= MIN_PAIRS:
            bins.append({"d_m": float(d[m].mean()), "correlation": float(q[m].mean()), "pairs": int(m.sum())})
    pos = [b for b in bins if b["correlation"] > 0]
    if not pos:
        return 0.0, LENGTH_RANGE_M[0], bins
    if len(pos) == 1:
        return pos[0]["correlation"], LENGTH_RANGE_M[0], bins
    x = np.array([b["d_m"] for b in pos])
    y = np.log([b["correlation"] for b in pos])
    w = np.sqrt([b["pairs"] for b in pos])
    slope, intercept = np.polyfit(x, y, 1, w=w)
    length = float(np.clip(-1.0 / slope, *LENGTH_RANGE_M)) if slope < 0 else LENGTH_RANGE_M[1]
    return float(np.exp(intercept)), length, bins


def variance_law(e2_m2: np.ndarray, acc2_m2: np.ndarray) -> tuple[float, float]:
    """(F, M) of E[e²] = F + M·accuracy² by least squares over the fixes (per-axis squared errors
    e2_m2, accuracy² acc2_m2), both kept ≥ 0 and M > 0 (a fit that wants F < 0 is all M; one that
    wants M ≤ 0 is all F, with M at :data:`MIN_PER_ACC2`)."""
    a = np.column_stack([np.ones_like(acc2_m2), acc2_m2])
    (f, m), *_ = np.linalg.lstsq(a, e2_m2, rcond=None)
    if f < 0:
        return 0.0, float(np.sum(e2_m2 * acc2_m2) / np.sum(acc2_m2**2))
    if m <= MIN_PER_ACC2:
        return float(np.mean(e2_m2) - MIN_PER_ACC2 * np.mean(acc2_m2)), MIN_PER_ACC2
    return float(f), float(m)


def model_of(residuals: Sequence[np.ndarray]) -> dict[str, Any] | None:
    """The fix-error model from per-walk residual arrays (rows: error x, error y [m], accuracy [m],
    distance walked along the truth [m]; time order), or None with fewer than :data:`MIN_FIXES` fixes:
    one fix's error covariance F + accuracy²·M (:func:`variance_law`, with the axes' shape) and the
    correlated part σ_c, ℓ (:func:`correlation`)."""
    rows = [np.asarray(r, float).reshape(-1, 4) for r in residuals]
    rows = [r[np.all(np.isfinite(r), axis=1) & (r[:, 2] > 0)] for r in rows]
    rows = [r for r in rows if len(r)]
    n = sum(len(r) for r in rows)
    if n < MIN_FIXES:
        return None
    raw = np.concatenate([r[:, :2] for r in rows])  # errors [m]
    cap = _winsorise(raw)
    acc = np.concatenate([r[:, 2] for r in rows])
    # the law on the raw errors: the worst fixes are the ones the matcher says are poor (a fix 70 m off
    # comes with an accuracy of 30 m), and that is the part of the law the gate depends on
    floor_m2, per_acc2 = variance_law(0.5 * np.sum(raw**2, axis=1), acc**2)
    # the axes' shape (a corridor's error runs along it), applied to both parts
    iso = float(np.mean(0.5 * np.sum(cap**2, axis=1)))
    shape = np.array([np.mean(cap[:, 0] ** 2), np.mean(cap[:, 0] * cap[:, 1]), np.mean(cap[:, 1] ** 2)]) / iso
    f_xx, f_xy, f_yy = (float(v) for v in floor_m2 * shape)
    m_xx, m_xy, m_yy = (float(v) for v in per_acc2 * shape)
    capped, start = [], 0
    for r in rows:
        capped.append(np.column_stack([cap[start : start + len(r)], r[:, 2:]]))
        start += len(r)
    share, length, bins = correlation(capped)
    share = min(max(share, 0.0), MAX_CORRELATED_SHARE)
    acc_med = float(np.median(acc))
    # c's variance in metres: the correlated share of one fix's variance at the median accuracy
    sigma_c = math.sqrt(share * (floor_m2 + per_acc2 * acc_med**2) * float(min(shape[0], shape[2])))
    return {
        "fixes": n,
        "floor_m2": floor_m2,
        "per_acc2": per_acc2,
        "m_xx": m_xx,
        "m_yy": m_yy,
        "m_xy": m_xy,
        "accuracy_median_m": acc_med,
        "correlated_share": share,
        "correlated_sigma_m": sigma_c,
        "correlation_length_m": length,
        "correlation_bins": bins,
        "site_fields": {
            "has_fix_model": True,
            "fix_floor_cov_m2": [f_xx, f_xy, f_yy],
            "fix_cov_per_acc2": [m_xx, m_xy, m_yy],
            "fix_bias_sigma_m": sigma_c,
            "fix_bias_length_m": length,
            "fix_white_share": 1.0 - share,
        },
    }


def model_sets(fields: dict[str, Any]) -> list[str]:
    """The --set list (KEYS) that gives the firmware the model of ``fields`` (site_t fix-model fields)
    without a site that carries it: the same numbers the site would hold."""
    f_xx, f_xy, f_yy = fields["fix_floor_cov_m2"]
    m_xx, m_xy, m_yy = fields["fix_cov_per_acc2"]
    bias = (fields["fix_bias_sigma_m"], fields["fix_bias_length_m"], fields["fix_white_share"])
    values = (m_xx, m_yy, m_xy, f_xx, f_yy, f_xy, *bias)
    return [f"{k}={v:.9g}" for k, v in zip(KEYS, values, strict=True)]


def measure(
    walks: list[dict[str, Any]],
    sites: Callable[[Any, list[dict[str, Any]], str, Path], list[str] | None],
    firmware: Firmware,
    work_dir: Path,
    base_sets: Sequence[str],
    block_sets: Mapping[int, Sequence[str]],
    tasks: TaskRunner,
    stream: TextIO,
    n_blocks: int = rs.DEFAULT_BLOCKS,
    cache: rs.ReplayCache | None = None,
    site_dir: Path | None = None,
) -> tuple[list[dict[str, Any] | None], list[float], dict[str, Any]]:
    """The model of every walk's fold (site_t fields, None where too few fixes), its σ_c, and the
    group's report (results.json)."""
    n_blocks = min(n_blocks, len(walks))
    prog = Progress("measure fix errors", (n_blocks - 1) * len(walks), stream)
    work_dir.mkdir(parents=True, exist_ok=True)
    block, results = rs.block_replays(
        walks,
        sites,
        stridefixd=firmware.path,
        work_dir=work_dir,
        base_sets=list(base_sets),
        candidates={"measured": []},
        tasks=tasks,
        n_blocks=n_blocks,
        progress=prog.step,
        replay=None,
        stage="fixmodel",
        block_sets=block_sets,
        cache=cache,
        site_dir=site_dir,
    )
    pooled: dict[int, list[np.ndarray]] = {a: [] for a in range(n_blocks)}
    for r in results:
        if r["errors"] is not None:
            pooled[r["a"]].append(r["errors"])
    models = {a: model_of(pooled[a]) for a in range(n_blocks)}
    report = {
        "measured_by": f"Wi-Fi fixes vs truth, {n_blocks} blocks, maps without the block",
        "blocks": {
            str(a): {k: v for k, v in (m or {"fixes": 0}).items() if k != "site_fields"}
            for a, m in models.items()
        },
    }
    fields = [(models[block[i]] or {}).get("site_fields") for i in range(len(walks))]
    sigma = [float((models[block[i]] or {}).get("correlated_sigma_m", math.nan)) for i in range(len(walks))]
    return fields, sigma, report
