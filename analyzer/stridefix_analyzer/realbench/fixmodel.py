"""The site's Wi-Fi fix-error model for the ``ekf`` scheme, measured on training walks the map never saw.

The matcher's ``accuracy_m`` is the spread of its neighbours, a shape rather than a calibrated σ
(issue 11: fixes whose real error is 5–6 m report 1.5–3 m). The ``ekf`` scheme takes its R as
``accuracy_m² · M`` (``firmware/core/sf_ekf.h``); this module measures M against the truth:

* the walks of a group are dealt into blocks and replayed with ``--fusion wifi_only`` on maps without
  their own block and the held-out block (:func:`.select.block_replays`, the same machinery as the
  matcher's inner cross-validation, with that block's matcher settings), so every residual is out of
  sample and none comes from the walk being scored;
* per held-out block a, M = mean over the fixes of u·uᵀ, u = e / accuracy (e = fix − truth, per
  axis: a corridor's error runs along it), pooled over the other blocks' walks; |u| is winsorised at
  its :data:`WINSOR_QUANTILE` quantile, because a fix outside the training walks' coverage is off by
  tens of metres and one of them would set M alone (the gate handles those);
* consecutive fixes err alike (neighbouring scans match the same wrong reference points), and a
  filter that takes them as independent follows them. With ρ the lag-1 autocorrelation of u (within
  each walk, both axes pooled), the errors as AR(1), the mean of N consecutive fixes has the variance
  of one fix times c = (1 + 2 Σ_{k<N} (1 − k/N) ρ^k) / N instead of 1 / N: the run carries the
  information of 1 / c fixes, not N: the run factor N·c (≤ N), N = :data:`RUN_FIXES` the run a
  converged filter effectively averages, multiplies R in the scheme's updates (not in its start,
  recovery or gate, which rest on one fix).

The result goes to the fold as ``ekf.fix_var_x_per_acc2``, ``ekf.fix_var_y_per_acc2``,
``ekf.fix_cov_xy_per_acc2`` (the firmware's prior, which the scheme can only raise online) and
``ekf.fix_run_factor``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.realbench import select as rs
from stridefix_analyzer.realbench.progress import Progress

#: fewest walks in a group to measure the model (fewer: the firmware prior)
MIN_WALKS = 3
#: ρ is clamped to [0, RHO_MAX]: a negative lag-1 correlation is noise
RHO_MAX = 1.0
#: fewest fixes per block for a model (fewer: the firmware prior for that block)
MIN_FIXES = 20
#: |u| above this quantile is pulled onto it
WINSOR_QUANTILE = 0.9
#: fixes a converged filter averages (a Kalman gain of ~0.2 per fix): the horizon of the correlation
#: factor
RUN_FIXES = 5
KEYS = ("ekf.fix_var_x_per_acc2", "ekf.fix_var_y_per_acc2", "ekf.fix_cov_xy_per_acc2", "ekf.fix_run_factor")


def model_of(residuals: Sequence[np.ndarray]) -> dict[str, Any] | None:
    """M (xx, yy, xy per accuracy²), ρ and the inflated model from per-walk residual arrays
    (rows: error x, error y, accuracy; time order), or None with fewer than :data:`MIN_FIXES` fixes."""
    rows = [np.asarray(r, float).reshape(-1, 3) for r in residuals]
    rows = [r[np.all(np.isfinite(r), axis=1) & (r[:, 2] > 0)] for r in rows]
    n = sum(len(r) for r in rows)
    if n < MIN_FIXES:
        return None
    u = [r[:, :2] / r[:, 2:3] for r in rows]  # errors per unit accuracy
    allu = np.concatenate(u)
    cap = float(np.quantile(np.hypot(allu[:, 0], allu[:, 1]), WINSOR_QUANTILE))
    radius = np.hypot(allu[:, 0], allu[:, 1])
    allu = allu * np.minimum(1.0, cap / np.maximum(radius, 1e-12))[:, None]
    m_xx, m_yy, m_xy = (
        float(np.mean(allu[:, 0] ** 2)),
        float(np.mean(allu[:, 1] ** 2)),
        float(np.mean(allu[:, 0] * allu[:, 1])),
    )
    lag = sum(float(np.sum(w[1:] * w[:-1])) for w in u if len(w) > 1)
    energy = sum(float(np.sum(w[:-1] ** 2)) for w in u if len(w) > 1)
    rho = min(max(lag / energy, 0.0), RHO_MAX) if energy > 0 else 0.0
    k = np.arange(1, RUN_FIXES)
    factor = float(1.0 + 2.0 * np.sum((1.0 - k / RUN_FIXES) * rho**k))
    return {
        "fixes": n,
        "m_xx": m_xx,
        "m_yy": m_yy,
        "m_xy": m_xy,
        "rho_lag1": rho,
        "factor": factor,
        "sets": [
            f"{KEYS[0]}={m_xx:.6g}",
            f"{KEYS[1]}={m_yy:.6g}",
            f"{KEYS[2]}={m_xy:.6g}",
            f"{KEYS[3]}={factor:.6g}",
        ],
    }


def measure(
    walks: list[dict[str, Any]],
    sites: Callable[[Any, list[dict[str, Any]], str, Path], list[str] | None],
    firmware: Firmware,
    work_dir: Path,
    base_sets: Sequence[str],
    block_sets: Mapping[int, Sequence[str]],
    jobs: int,
    stream: TextIO,
    n_blocks: int = rs.DEFAULT_BLOCKS,
) -> tuple[list[list[str]], list[float], dict[str, Any]]:
    """The model of every walk's fold (as settings; [] where too few fixes), its inflation factor,
    and the group's report (results.json)."""
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
        jobs=jobs,
        n_blocks=n_blocks,
        progress=prog.step,
        replay=rs.replay_task,
        stage="fixmodel",
        block_sets=block_sets,
    )
    pooled: dict[int, list[np.ndarray]] = {a: [] for a in range(n_blocks)}
    for r in results:
        if r["errors"] is not None:
            pooled[r["a"]].append(r["errors"])
    models = {a: model_of(pooled[a]) for a in range(n_blocks)}
    report = {
        "measured_by": f"Wi-Fi fixes vs truth, {n_blocks} blocks, maps without the block",
        "blocks": {
            str(a): {k: v for k, v in (m or {"fixes": 0}).items() if k != "sets"} for a, m in models.items()
        },
    }
    sets = [list((models[block[i]] or {}).get("sets", [])) for i in range(len(walks))]
    factor = [float((models[block[i]] or {}).get("factor", math.nan)) for i in range(len(walks))]
    return sets, factor, report
