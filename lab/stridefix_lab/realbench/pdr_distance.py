"""``stridefix-lab realbench pdr-distance``: how well step detection + Weinberg step length measure distance
walked, on the Microsoft Indoor Location Competition 2.0 traces of one floor.

For every trace of the floor: import it through the data-set protocol (the ``.lcmlog`` is cached under
``OUT/cache``, :func:`.walks.cached_import`), replay it through ``stridefixd --input lcmlog:FILE``,
read its ``STEP`` messages (``accel_range_mps2`` = vertical acceleration amax − amin over the step) and
the ``TRUTH`` waypoints. Segments, Weinberg sums and the leave-one-walk-out calibrations are
:mod:`stridefix_analyzer.radiomap.strides`: K_i from every *other* walk of the floor, PDR distance = K_i · W, error % =
100 |PDR − true| / true; baseline: a fixed stride (median true / n_steps of the other walks) × n_steps;
also reported: the firmware's own ``length_m`` sum as configured.

Outputs in ``--out DIR``: ``realbench_pdr_distance.json`` (summary, per-walk and per-segment rows; non-
finite numbers as null) and ``realbench_pdr_distance.png`` (:mod:`.pdr_plot`).
Exit status: 0 done, 1 nothing could be scored, 2 bad usage or unreadable input (no traces, no
stridefixd).

Straight-line truth between waypoints underestimates the distance of a segment that bends, so the
errors include the surveyor's path shape; K absorbs the floor-wide average of that bias.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from stridefix_analyzer.console import Progress
from stridefix_analyzer.datasets.protocol import DEFAULT_MAX_WIFI_AGE_S, DatasetReadError
from stridefix_analyzer.firmware import Firmware, FirmwareError
from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.io.logread import LogReadError, LogTruncatedWarning, Table, read_logs
from stridefix_analyzer.parallel import WorkerFiles, is_remote, task_runner
from stridefix_analyzer.radiomap.strides import (
    DEFAULT_MIN_SEGMENT_M,
    IMU_COVER_TOLERANCE_S,
    SUSPECT_SLOW_MPS,
    SUSPECT_SPEED_MPS,
    WEINBERG_EXPONENT,
    build_segments,
    calibrate_lowo,
    spread,
    stride_lowo,
)
from stridefix_analyzer.radiomap.strides import error_stats as error_stats

from stridefix_lab.realbench.pdr_plot import plot_pdr_distance
from stridefix_lab.realbench.walks import cached_import, dataset, find_groups, firmware, new_walk

#: The data set whose floors this benchmark reads.
DATASET = "msindoor"
DEFAULT_OUT = os.path.join("out", "realbench")
JSON_FILE = "realbench_pdr_distance.json"
PNG_FILE = "realbench_pdr_distance.png"
#: The target of the benchmark: median absolute segment distance error [%].
TARGET_MEDIAN_ABS_ERROR_PCT = 5.0
#: Segment length bins of the error breakdown [m].
LENGTH_BINS_M = (3.0, 5.0, 10.0, math.inf)


def prepare_walk(
    trace: str | Path,
    out_dir: str | Path,
    fw: Firmware,
    max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S,
    reimport: bool = False,
) -> dict[str, Any]:
    """Import one trace (cached), replay it through the firmware, read STEP and TRUTH.

    Returns
    -------
    dict
        ``trace``, ``walk`` (the trace's stem), ``import`` (importer summary), ``error`` (None or the
        reason the walk could not be run), and when it ran: ``waypoint_t_us`` (w,), ``waypoint_xy_m``
        (w, 2), ``step_t_us`` (s,), ``step_range_mps2`` (s,), ``step_length_m`` (s,),
        ``health`` (last HEALTH fields), ``warnings``.
    """
    trace, out_dir = Path(trace), Path(out_dir)
    walk = new_walk(trace)
    cache_dir, fw_dir = out_dir / "cache", out_dir / "stridefixd"
    cache_dir.mkdir(parents=True, exist_ok=True)
    fw_dir.mkdir(parents=True, exist_ok=True)
    try:
        options = {"max_wifi_age_s": max_wifi_age_s}
        summary = cached_import(dataset(DATASET), trace, cache_dir, options, reimport)
    except (DatasetReadError, OSError) as exc:
        walk["error"] = f"import failed: {exc}"
        return walk
    walk["import"] = summary
    walk["warnings"] += summary.get("warnings", [])
    fw_log = fw_dir / f"{trace.stem}.lcmlog"
    try:
        fw.run(input=f"lcmlog:{summary['out']}", log=fw_log, sets=dataset(DATASET).firmware_sets)
    except FirmwareError as exc:
        walk["error"] = str(exc)
        return walk
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)
            data = read_logs([fw_log, summary["out"]], decode=("STEP", "TRUTH", "HEALTH"))
    except LogReadError as exc:
        walk["error"] = f"cannot read logs: {exc}"
        return walk
    walk["warnings"] += data.warnings
    truth = data.table("TRUTH")
    steps = data.table("STEP")
    walk["waypoint_t_us"] = truth["t_us"] if truth is not None else np.zeros(0, np.int64)
    walk["waypoint_xy_m"] = (
        np.column_stack([truth["x_m"], truth["y_m"]]) if truth is not None else np.zeros((0, 2))
    )
    empty = np.zeros(0)
    walk["step_t_us"] = steps["t_us"] if steps is not None else np.zeros(0, np.int64)
    walk["step_range_mps2"] = steps["accel_range_mps2"] if steps is not None else empty
    walk["step_length_m"] = steps["length_m"] if steps is not None else empty
    walk["health"] = data.health
    return walk


def score_segments(seg: Table, n_walks: int) -> tuple[Table, dict]:
    """Calibrate (LOWO) and score the segments; returns the table with scores added and the fits.

    Added columns: ``K``, ``pdr_m`` (K·weinberg), ``err_pct`` (signed, 100 (pdr − true)/true),
    ``stride_m``, ``baseline_m`` (stride·n_steps), ``baseline_err_pct``, ``fw_err_pct``; NaN on
    excluded rows.
    """
    used = seg["excluded"] == ""
    walks = np.arange(n_walks)
    k = calibrate_lowo(seg["walk"][used], seg["true_m"][used], seg["weinberg"][used], walks)
    stride = stride_lowo(seg["walk"][used], seg["true_m"][used], seg["n_steps"][used], walks)
    cols = seg.to_dict()
    nan = np.full(len(seg), math.nan)
    kk = np.where(used, k[seg["walk"]] if len(seg) else nan, nan)
    ss = np.where(used, stride[seg["walk"]] if len(seg) else nan, nan)
    true = seg["true_m"]
    with np.errstate(invalid="ignore", divide="ignore"):
        cols["K"] = kk
        cols["pdr_m"] = kk * seg["weinberg"]
        cols["err_pct"] = 100 * (cols["pdr_m"] - true) / true
        cols["stride_m"] = ss
        cols["baseline_m"] = ss * seg["n_steps"]
        cols["baseline_err_pct"] = 100 * (cols["baseline_m"] - true) / true
        cols["fw_err_pct"] = np.where(used, 100 * (seg["fw_length_m"] - true) / true, nan)
    all_w = seg["weinberg"][used].sum()
    fits = {
        "K": k,
        "stride_m": stride,
        "K_all_walks": float(seg["true_m"][used].sum() / all_w) if all_w > 0 else math.nan,
    }
    return Table(cols), fits


# --- the benchmark ---------------------------------------------------------------------------------


def run_pdr_distance(
    floor_dir: str | Path,
    stridefixd: str | Path | None = None,
    out_dir: str | Path | None = None,
    limit: int | None = None,
    min_segment_m: float = DEFAULT_MIN_SEGMENT_M,
    max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S,
    jobs: int | None = None,
    reimport: bool = False,
    progress: bool = False,
    plot: bool = True,
    scheduler: str | None = "processes",
) -> dict[str, Any]:
    """Run the PDR distance benchmark on one floor; write JSON (+ PNG) into ``out_dir``.

    ``stridefixd`` None: :func:`stridefix_analyzer.firmware.default_path`. ``progress``: the walks'
    preparation as a :class:`stridefix_analyzer.console.Progress` on stderr. The walks are prepared on
    ``scheduler`` with ``jobs`` workers (:mod:`stridefix_analyzer.parallel`). Returns the JSON document
    (a dict; non-finite numbers still as NaN).

    Raises
    ------
    RealbenchError
        No traces, or no executable ``stridefixd``.
    SchedulerError
        The scheduler cannot be reached, or a Dask worker lacks the data or the build.
    """
    t_start = time.perf_counter()
    if is_remote(scheduler):  # a remote worker's working folder is not ours
        floor_dir = Path(floor_dir).resolve()
        stridefixd = Path(stridefixd or Firmware().path).resolve()
    (group,) = find_groups(dataset(DATASET), [floor_dir], limit)
    label, traces = group.label, group.walks
    fw = firmware(stridefixd or Firmware().path)
    out = Path(out_dir or os.path.join(DEFAULT_OUT, label.replace("/", "-")))
    out = out.resolve() if is_remote(scheduler) else out
    out.mkdir(parents=True, exist_ok=True)
    n_jobs = max(1, jobs or os.cpu_count() or 1)
    prog = Progress("walk", len(traces), sys.stderr if progress else None)

    def prepared(_: int, w: dict[str, Any]) -> None:
        state = w["error"] or (f"{len(w['step_t_us'])} steps, {len(w['waypoint_t_us'])} waypoints")
        prog.step(f"{w['walk']}: {state}")

    files = WorkerFiles(read=[floor_dir], write=[out], same=[fw.path])
    with task_runner(scheduler, n_jobs, files) as runner:
        shared = (out, fw, max_wifi_age_s, reimport)
        walks = runner.map(_prepare_task, traces, shared=shared, on_result=prepared)

    seg, fits = score_segments(build_segments(walks, min_segment_m), len(walks))
    doc = summarize(label, floor_dir, walks, seg, fits, min_segment_m, max_wifi_age_s, limit)
    doc["stridefixd"] = {"path": str(fw.path), "version": fw.version()}
    doc["out_dir"] = str(out)
    doc["run_s"] = time.perf_counter() - t_start
    with open(out / JSON_FILE, "w", encoding="utf-8") as f:
        json.dump(json_ready(doc), f, indent=1, allow_nan=False)
        f.write("\n")
    if plot:
        (out / PNG_FILE).write_bytes(plot_pdr_distance(seg, label, TARGET_MEDIAN_ABS_ERROR_PCT))
    return doc


def _prepare_task(trace: Path, shared: tuple[Path, Firmware, float, bool]) -> dict[str, Any]:
    """:func:`prepare_walk` of one trace, as a task (the other arguments are the run's)."""
    return prepare_walk(trace, *shared)


def summarize(
    label: str,
    floor_dir: str | Path,
    walks: list[dict[str, Any]],
    seg: Table,
    fits: dict[str, Any],
    min_segment_m: float,
    max_wifi_age_s: float,
    limit: int | None,
) -> dict[str, Any]:
    """The JSON document of one run (see the module docstring)."""
    used = seg["excluded"] == ""
    excluded: dict[str, int] = {}
    for reason in seg["excluded"][~used]:
        excluded[reason] = excluded.get(reason, 0) + 1
    ok_walks = [i for i, w in enumerate(walks) if not w["error"]]
    scored_walks = sorted(set(seg["walk"][used].tolist()))
    weinberg = error_stats(seg["err_pct"][used])
    per_walk = []
    for i, w in enumerate(walks):
        mine = used & (seg["walk"] == i)
        imp = w.get("import") or {}
        per_walk.append(
            {
                "walk": w["walk"],
                "trace": w["trace"],
                "error": w["error"],
                "duration_s": imp.get("duration_s"),
                "waypoints": imp.get("waypoints"),
                "steps": int(len(w["step_t_us"])) if "step_t_us" in w else None,
                "segments_scored": int(mine.sum()),
                "true_m": float(seg["true_m"][mine].sum()),
                "K": fits["K"][i],
                "stride_m": fits["stride_m"][i],
                "median_abs_err_pct": error_stats(seg["err_pct"][mine])["median"],
                "skipped_lines": imp.get("skipped_lines"),
                "warnings": w["warnings"][:10],
            }
        )
    k_scored = fits["K"][scored_walks] if scored_walks else np.zeros(0)
    steps_in_segments = int(seg["n_steps"][used].sum())
    return {
        "benchmark": "pdr-distance",
        "floor": label,
        "floor_dir": str(floor_dir),
        "params": {
            "min_segment_m": min_segment_m,
            "max_wifi_age_s": max_wifi_age_s,
            "limit": limit,
            "weinberg_exponent": WEINBERG_EXPONENT,
            "imu_cover_tolerance_s": IMU_COVER_TOLERANCE_S,
            "suspect_speed_mps": [SUSPECT_SLOW_MPS, SUSPECT_SPEED_MPS],
        },
        "target": {
            "median_abs_error_pct_max": TARGET_MEDIAN_ABS_ERROR_PCT,
            "met": bool(weinberg["n"] and weinberg["median"] <= TARGET_MEDIAN_ABS_ERROR_PCT),
        },
        "walks": {
            "n": len(walks),
            "ran": len(ok_walks),
            "scored": len(scored_walks),
            "failed": [
                {"walk": walks[i]["walk"], "error": walks[i]["error"]}
                for i in range(len(walks))
                if walks[i]["error"]
            ],
        },
        "segments": {
            "n": len(seg),
            "scored": int(used.sum()),
            "excluded": excluded,
            "true_m_scored": float(seg["true_m"][used].sum()),
            "suspect_speed_scored": int((seg["suspect"] & used).sum()),
            "zero_steps_scored": int(((seg["n_steps"] == 0) & used).sum()),
            "steps_scored": steps_in_segments,
            "bad_range_steps": int(seg["bad_range"][used].sum()),
        },
        "weinberg_lowo": {
            "abs_error_pct": weinberg,
            "abs_error_pct_by_length_m": _by_length(seg, used),
            "abs_error_pct_unflagged": error_stats(seg["err_pct"][used & ~seg["suspect"]]),
            "signed_error_pct_median": _median(seg["err_pct"][used]),
            "K": {**spread(k_scored), "all_walks": fits["K_all_walks"]},
        },
        "baseline_fixed_stride_lowo": {
            "abs_error_pct": error_stats(seg["baseline_err_pct"][used]),
            "signed_error_pct_median": _median(seg["baseline_err_pct"][used]),
            "stride_m": spread(fits["stride_m"][scored_walks] if scored_walks else []),
        },
        "firmware_length_as_configured": {
            "abs_error_pct": error_stats(seg["fw_err_pct"][used]),
            "signed_error_pct_median": _median(seg["fw_err_pct"][used]),
        },
        "per_walk": per_walk,
        "segment_rows": [
            {"walk": walks[int(r["walk"])]["walk"], **{n: r[n] for n in seg.names if n != "walk"}}
            for r in (_row(seg, i) for i in range(len(seg)))
        ],
    }


def _by_length(seg: Table, used: np.ndarray) -> dict:
    out = {}
    for lo, hi in zip(LENGTH_BINS_M[:-1], LENGTH_BINS_M[1:]):
        m = used & (seg["true_m"] >= lo) & (seg["true_m"] < hi)
        out[f"{lo:g}-{hi:g}"] = error_stats(seg["err_pct"][m])
    return out


def _row(t: Table, i: int) -> dict:
    return {n: t[n][i].item() if hasattr(t[n][i], "item") else t[n][i] for n in t.names}


def _median(values: ArrayLike) -> float:
    x = np.asarray(values, float)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if len(x) else math.nan


def missed_targets(doc: dict[str, Any]) -> list[str]:
    """One line per missed target of a pdr-distance document (empty when every target is met)."""
    t = doc["target"]
    if t["met"]:
        return []
    med = doc["weinberg_lowo"]["abs_error_pct"]["median"]
    shown = "n/a" if med is None or not math.isfinite(med) else f"{med:.2f}"
    return [
        f"realbench pdr-distance [{doc['floor']}]: median |distance error| (Weinberg, leave one walk out) "
        f"= {shown} % (target <= {t['median_abs_error_pct_max']:g} %)"
    ]


def format_table(doc: dict) -> str:
    """A readable plain-text table of one floor's results."""

    def f(v: Any, d: int = 2) -> str:
        return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{d}f}"

    seg, wk = doc["segments"], doc["walks"]
    k = doc["weinberg_lowo"]["K"]
    lines = [
        f"PDR distance on {doc['floor']}: {wk['n']} walks ({wk['ran']} ran, {wk['scored']} "
        f"scored), {seg['n']} segments, {seg['scored']} scored ({seg['true_m_scored']:.0f} m, "
        f"{seg['steps_scored']} steps)"
    ]
    if seg["excluded"]:
        lines.append("  excluded: " + ", ".join(f"{n} {r}" for r, n in sorted(seg["excluded"].items())))
    slow, fast = doc["params"]["suspect_speed_mps"]
    lines.append(
        f"  flagged (kept): {seg['suspect_speed_scored']} segment(s) with implied speed "
        f"outside {slow:g}..{fast:g} m/s, {seg['zero_steps_scored']} with no step"
    )
    cols = ["n", "median", "mean", "p75", "p90", "p95", "max"]
    lines.append(f"  {'abs error %':<34}" + "".join(f"{c:>8}" for c in cols) + f"{'bias%':>8}")
    for name, key in (
        ("Weinberg, K leave-one-walk-out", "weinberg_lowo"),
        ("fixed stride (LOWO median) x steps", "baseline_fixed_stride_lowo"),
        ("firmware length_m as configured", "firmware_length_as_configured"),
    ):
        e = doc[key]["abs_error_pct"]
        lines.append(
            f"  {name:<34}"
            + "".join(f"{(str(e[c]) if c == 'n' else f(e[c], 1)):>8}" for c in cols)
            + f"{f(doc[key]['signed_error_pct_median'], 1):>8}"
        )
    wl = doc["weinberg_lowo"]
    lines.append(
        "  Weinberg median abs error % by segment length: "
        + ", ".join(
            f"{b} m: {f(e['median'], 1)} (n {e['n']})" for b, e in wl["abs_error_pct_by_length_m"].items()
        )
        + f"; unflagged only: {f(wl['abs_error_pct_unflagged']['median'], 1)} "
        f"(n {wl['abs_error_pct_unflagged']['n']})"
    )
    st = doc["baseline_fixed_stride_lowo"]["stride_m"]
    lines.append(
        f"  K over folds: mean {f(k['mean'], 4)}, std {f(k['std'], 4)}, "
        f"range {f(k['min'], 4)}..{f(k['max'], 4)}; all walks {f(k['all_walks'], 4)}"
        f"   stride: mean {f(st['mean'], 3)} m ({f(st['min'], 3)}..{f(st['max'], 3)})"
    )
    t = doc["target"]
    med = doc["weinberg_lowo"]["abs_error_pct"]["median"]
    lines.append(
        f"  target: median abs error <= {t['median_abs_error_pct_max']:g} %: "
        f"{f(med, 2)} % -> {'MET' if t['met'] else 'NOT MET'}"
    )
    for w in wk["failed"]:
        lines.append(f"  failed walk {w['walk']}: {w['error']}")
    return "\n".join(lines)
