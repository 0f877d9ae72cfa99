"""Where dead reckoning goes wrong on a real walk: its STEP stream against the truth, segment by segment.

A *segment* is two consecutive ground-truth waypoints k, k+1 (times t_k < t_{k+1}); its steps are the
STEP messages with t_k < t ≤ t_{k+1}. Per segment:

* ``heading_err_rad``: the angle of the PDR displacement Σ length·(cos h, sin h) over its steps minus
  the truth direction atan2(Δy, Δx), wrapped to (−π, π]; only on *straight* segments (truth at least
  ``min_segment_m`` long, ≥ ``min_steps`` steps whose unit headings have a resultant length ≥
  ``min_resultant``: the walker went straight from one point to the next), NaN otherwise;
* ``dist_ratio``: Σ length / truth distance (straight segments; > 1 too long, < 1 too short);
* ``n_steps`` and, on segments the truth says were walked at under ``still_mps`` (a pause at a
  waypoint, the phone handled), the steps counted there (``still_steps``).

Steps before the first waypoint (the calibration gestures of a GetSensorData log) are counted apart:
a truth-initialised replay that counts them moves off its start point before the walk begins, by
``pre_walk_m`` (the length of their PDR displacement).

:func:`segment_table` does one walk from arrays, :func:`walk_summary` reduces it to one row,
:func:`realbench_table` reads a ``realbench fusion --true-start`` result (its replays' STEP streams and
the imported truth) into one row per walk. Heading is judged in the map frame of the replay: the
fold's map rotation (learned on the other walks) is in the STEP headings already.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from stridefix_analyzer.radiomap.heading import is_straight
from stridefix_analyzer.scoring.metrics import wrap_pi

#: a segment shorter than this [m] has no usable direction (waypoint spacing in the IPIN logs: ~5–20 m)
MIN_SEGMENT_M = 3.0
#: straight: at least this many steps, their unit headings' resultant length at least this
MIN_STEPS = 3
MIN_RESULTANT = 0.9
#: a segment walked at less than this [m/s] is a pause (normal walking is 1.0–1.5 m/s; a slow walker
#: with pauses still exceeds 0.5): steps counted there were counted while standing or handling
STILL_MPS = 0.2

SEGMENT_KEYS = (
    "k",
    "t0_us",
    "t1_us",
    "true_m",
    "n_steps",
    "pdr_m",
    "straight",
    "heading_err_rad",
    "dist_ratio",
)


def segment_table(
    step_t_us: ArrayLike,
    step_heading_rad: ArrayLike,
    step_length_m: ArrayLike,
    wp_t_us: ArrayLike,
    wp_xy_m: ArrayLike,
    min_segment_m: float = MIN_SEGMENT_M,
    min_steps: int = MIN_STEPS,
    min_resultant: float = MIN_RESULTANT,
) -> dict[str, np.ndarray]:
    """Per segment of one walk: ``k``, ``t0_us``, ``t1_us``, ``true_m`` (straight-line truth [m]),
    ``n_steps``, ``pdr_m`` (Σ length [m]), ``straight`` (bool), ``heading_err_rad`` (NaN unless
    straight), ``dist_ratio`` (NaN unless straight). Arrays of length n_waypoints − 1."""
    t = np.asarray(step_t_us, np.int64)
    h = np.asarray(step_heading_rad, float)
    ln = np.asarray(step_length_m, float)
    wt = np.asarray(wp_t_us, np.int64)
    wp = np.asarray(wp_xy_m, float).reshape(-1, 2)
    n = max(len(wt) - 1, 0)
    out = {k: np.full(n, np.nan) for k in SEGMENT_KEYS}
    out["straight"] = np.zeros(n, bool)
    for k in range(n):
        i0, i1 = np.searchsorted(t, [wt[k], wt[k + 1]], side="right")
        hs, ls = h[i0:i1], ln[i0:i1]
        ok = np.isfinite(hs) & np.isfinite(ls)
        hs, ls = hs[ok], ls[ok]
        d = wp[k + 1] - wp[k]
        true_m = float(np.hypot(*d))
        out["k"][k], out["t0_us"][k], out["t1_us"][k] = k, wt[k], wt[k + 1]
        out["true_m"][k], out["n_steps"][k], out["pdr_m"][k] = true_m, len(hs), float(ls.sum())
        straight = is_straight(true_m, hs, min_segment_m, min_steps, min_resultant)
        out["straight"][k] = straight
        if straight:
            dx, dy = float((ls * np.cos(hs)).sum()), float((ls * np.sin(hs)).sum())
            out["heading_err_rad"][k] = float(wrap_pi(math.atan2(dy, dx) - math.atan2(d[1], d[0])))
            out["dist_ratio"][k] = float(ls.sum()) / true_m
    return out


def walk_summary(
    seg: Mapping[str, np.ndarray],
    step_t_us: ArrayLike,
    step_heading_rad: ArrayLike,
    step_length_m: ArrayLike,
    wp_t_us: ArrayLike,
    still_mps: float = STILL_MPS,
) -> dict[str, Any]:
    """One walk's row: ``segments``, ``straight``, ``heading_err_median_deg`` (median |error| over
    straight segments), ``heading_err_max_deg``, ``heading_err_mean_deg`` (signed circular mean: the
    constant part, a wrong device-to-walk angle or map rotation), ``dist_ratio_median``,
    ``dist_ratio_total`` (Σ PDR / Σ truth over straight segments), ``steps``, ``still_steps`` (steps
    on segments walked under ``still_mps``), ``pre_walk_steps`` and ``pre_walk_m`` (before the first
    waypoint)."""
    t = np.asarray(step_t_us, np.int64)
    h, ln = np.asarray(step_heading_rad, float), np.asarray(step_length_m, float)
    wt = np.asarray(wp_t_us, np.int64)
    st = np.asarray(seg["straight"], bool)
    err = np.asarray(seg["heading_err_rad"], float)[st]
    dur_s = (np.asarray(seg["t1_us"]) - np.asarray(seg["t0_us"])) * 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        speed = np.asarray(seg["true_m"]) / dur_s
    still = speed < still_mps
    pre = t <= wt[0] if len(wt) else np.zeros(len(t), bool)
    pre_dx = float((ln[pre] * np.cos(h[pre])).sum()) if pre.any() else 0.0
    pre_dy = float((ln[pre] * np.sin(h[pre])).sum()) if pre.any() else 0.0
    nan = math.nan
    return {
        "segments": len(st),
        "straight": int(st.sum()),
        "heading_err_median_deg": math.degrees(float(np.median(np.abs(err)))) if len(err) else nan,
        "heading_err_max_deg": math.degrees(float(np.max(np.abs(err)))) if len(err) else nan,
        "heading_err_mean_deg": math.degrees(math.atan2(np.sin(err).mean(), np.cos(err).mean()))
        if len(err)
        else nan,
        "dist_ratio_median": float(np.median(np.asarray(seg["dist_ratio"])[st])) if st.any() else nan,
        "dist_ratio_total": float(np.asarray(seg["pdr_m"])[st].sum() / np.asarray(seg["true_m"])[st].sum())
        if st.any()
        else nan,
        "steps": int(((t > wt[0]) & (t <= wt[-1])).sum()) if len(wt) else 0,
        "still_steps": int(np.asarray(seg["n_steps"])[still].sum()),
        "pre_walk_steps": int(pre.sum()),
        "pre_walk_m": math.hypot(pre_dx, pre_dy),
    }


def realbench_table(
    results_json: str | Path, tag: str = "true_start", cache: str | Path | None = None
) -> list[dict[str, Any]]:
    """One row per walk of a ``realbench fusion --true-start`` result: :func:`walk_summary` of the
    walk's truth-initialised replay (``tag``) plus ``walk`` and ``pdr_mean_m`` (pdr_only's mean error
    at the truth times). The STEP stream comes from the replay log in the walk's work folder, the
    truth from its imported log in the import cache (``cache``, default: ``cache`` beside the result,
    as ``realbench fusion`` makes it)."""
    from stridefix_analyzer.io.logread import read_table
    from stridefix_analyzer.io.results import read_realbench_results, walk_scores

    path = Path(results_json)
    doc = read_realbench_results(path)
    cache_dir = Path(cache) if cache is not None else path.parent / "cache"
    rows = []
    for group in doc["groups"]:
        for w in group.get("walk_rows", []):
            if w.get("error") or tag not in w:
                continue
            wdir = Path(w["dir"])
            fw_log = wdir / ("stridefixd.lcmlog" if tag == "fixes" else f"stridefixd_{tag}.lcmlog")
            imports = sorted(cache_dir.glob(f"**/{w['walk']}.lcmlog"))
            if not fw_log.exists() or not imports:
                continue
            steps, truth = read_table(fw_log, "STEP"), read_table(imports[0], "TRUTH")
            if steps is None or truth is None or not len(truth):
                continue
            args = (steps["t_us"], steps["heading_rad"], steps["length_m"])
            wp_xy = np.column_stack([truth["x_m"], truth["y_m"]])
            seg = segment_table(*args, truth["t_us"], wp_xy)
            pdr = walk_scores(w, tag).get("pdr_only")
            row = {"walk": w["walk"], "pdr_mean_m": pdr.get("mean", math.nan) if pdr else math.nan}
            row.update(walk_summary(seg, *args, truth["t_us"]))
            rows.append(row)
    return rows


def format_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """The rows as a fixed-width text table, with a pooled last line (means of the per-walk figures,
    the median of their heading medians)."""
    cols = [
        ("walk", "{:<44}", "walk"),
        ("pdr_mean_m", "{:>7.2f}", "pdr m"),
        ("heading_err_median_deg", "{:>7.1f}", "hdg med"),
        ("heading_err_mean_deg", "{:>7.1f}", "hdg bias"),
        ("heading_err_max_deg", "{:>7.1f}", "hdg max"),
        ("dist_ratio_median", "{:>6.2f}", "dist"),
        ("steps", "{:>6d}", "steps"),
        ("still_steps", "{:>6d}", "still"),
        ("pre_walk_steps", "{:>6d}", "pre"),
        ("pre_walk_m", "{:>6.1f}", "pre m"),
    ]
    widths = [len(fmt.format(0 if "d" in fmt else 0.0)) for _, fmt, _ in cols[1:]]
    lines = [f"{'walk':<44} " + " ".join(f"{t:>{w}}" for (_, _, t), w in zip(cols[1:], widths, strict=True))]
    for r in rows:
        lines.append(" ".join(fmt.format(r[k]) for k, fmt, _ in cols))
    if rows:

        def col(k: str) -> np.ndarray:
            return np.array([r[k] for r in rows], float)

        lines.append(
            f"{'mean of ' + str(len(rows)) + ' walks':<44} {np.nanmean(col('pdr_mean_m')):>7.2f} "
            f"{np.nanmedian(col('heading_err_median_deg')):>7.1f} {np.nanmean(np.abs(col('heading_err_mean_deg'))):>7.1f} "
            f"{np.nanmax(col('heading_err_max_deg')):>7.1f} {np.nanmedian(col('dist_ratio_median')):>6.2f} "
            f"{int(col('steps').sum()):>6d} {int(col('still_steps').sum()):>6d} {int(col('pre_walk_steps').sum()):>6d} "
            f"{np.nanmean(col('pre_walk_m')):>6.1f}"
        )
    return "\n".join(lines)
