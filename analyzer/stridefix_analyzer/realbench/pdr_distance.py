"""``stridefix realbench``: benchmarks of the real firmware on real public data.

``fusion`` (the default: ``stridefix realbench --format msindoor|gsd DIR... --out results.json``):
every fusion scheme, leave one walk out; see :mod:`stridefix_analyzer.realbench_fusion`.

``pdr-distance``: how well step detection + Weinberg step length measure distance walked, on the
Microsoft Indoor Location Competition 2.0 traces of one floor.

For every trace of the floor: import it (``stridefix_analyzer.datasets.msindoor``; the ``.lcmlog`` is
cached under ``OUT/cache``), replay it through ``stridefixd --input lcmlog:FILE``, read its ``STEP``
messages (``accel_range_mps2`` = vertical acceleration amax − amin over the step) and the ``TRUTH``
waypoints.

- Segment = two consecutive waypoints k, k+1 of a walk; true distance = the straight line between them
  [m]; Weinberg sum W = Σ range^¼ over the steps with t_k < t_step ≤ t_{k+1}; n_steps = their count.
- Calibration, leave one walk out (DESIGN.md evaluation protocol): K_i = Σ true / Σ W over the scored
  segments of every *other* walk of the floor. PDR distance = K_i · W; error % = 100 |PDR − true| / true.
- Baseline without step length model: fixed stride = median over the other walks' segments of
  true / n_steps, times n_steps. Also reported: the firmware's own ``length_m`` sum as configured.
- Segments are excluded (counted, with the reason) when shorter than ``min_segment_m``, of zero
  duration, not covered by IMU data, or when the walk's import or firmware run failed. Nothing else
  is dropped; segments whose implied walking speed is implausible are flagged, not excluded.

Outputs in ``--out DIR``: ``realbench_pdr_distance.json`` (summary, per-walk and per-segment rows; non-
finite numbers as null) and ``realbench_pdr_distance.png`` (PDR vs true distance, error CDF).
Exit status: 0 done, 1 nothing could be scored, 2 bad usage or unreadable input (no traces, no
stridefixd).

Straight-line truth between waypoints underestimates the distance of a segment that bends, so the
errors include the surveyor's path shape; K absorbs the floor-wide average of that bias.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import json
import math
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.io.logread import LogReadError, LogTruncatedWarning, Table, read_logs

REPO = Path(__file__).resolve().parents[2]
DEFAULT_STRIDEFIXD = REPO / "build" / "firmware" / "stridefixd"
DEFAULT_OUT = os.path.join("out", "realbench")
JSON_FILE = "realbench_pdr_distance.json"
PNG_FILE = "realbench_pdr_distance.png"
DEFAULT_MIN_SEGMENT_M = 3.0
#: The target of the benchmark: median absolute segment distance error [%].
TARGET_MEDIAN_ABS_ERROR_PCT = 5.0
#: Waypoints this far outside the IMU data [s] still count as covered (sensor start-up jitter).
IMU_COVER_TOLERANCE_S = 0.5
#: Segments implying a walk faster / slower than these [m/s] are flagged as suspect (not excluded):
#: too fast = waypoint times off; too slow = a stop, a detour or a turn-around between the waypoints,
#: where the straight line underestimates the distance walked.
SUSPECT_SPEED_MPS = 2.5
SUSPECT_SLOW_MPS = 0.5
#: Segment length bins of the error breakdown [m].
LENGTH_BINS_M = (3.0, 5.0, 10.0, math.inf)
WEINBERG_EXPONENT = 0.25


class RealbenchError(RuntimeError):
    """The benchmark cannot run (no traces, no firmware binary). The message says what is missing."""


# --- inputs ----------------------------------------------------------------------------------------


def find_traces(floor_dir) -> tuple[str, list[Path]]:
    """The floor's label (``site1/F2``) and its trace files, sorted.

    ``floor_dir`` is either the floor folder or its ``path_data_files`` folder.

    Raises
    ------
    RealbenchError
        The folder does not exist or holds no ``*.txt`` trace.
    """
    d = Path(floor_dir)
    if not d.is_dir():
        raise RealbenchError(f"{d}: no such directory")
    if (d / "path_data_files").is_dir():
        d = d / "path_data_files"
    traces = sorted(d.glob("*.txt"))
    if not traces:
        raise RealbenchError(f"{d}: no *.txt trace files")
    floor = d.parent if d.name == "path_data_files" else d
    return f"{floor.parent.name}/{floor.name}", traces


def _cached_import(
    trace: Path,
    cache_dir: Path,
    max_wifi_age_s: float,
    reimport: bool,
    importer=None,
    import_kwargs: dict | None = None,
) -> dict:
    """Import ``trace`` into ``cache_dir/<stem>.lcmlog`` unless an up-to-date copy is there.

    ``importer``: the importer module (default ``stridefix_analyzer.datasets.msindoor``); it provides
    ``import_trace(path, out_path[, max_wifi_age_s=], **import_kwargs)`` and ``IMPORTER_VERSION``.
    ``import_kwargs`` (JSON-able values) are part of the cache key.
    """
    import inspect

    if importer is None:
        from stridefix_analyzer.datasets import msindoor as importer

    log = cache_dir / f"{trace.stem}.lcmlog"
    meta = cache_dir / f"{trace.stem}.import.json"
    st = trace.stat()
    key = {
        "trace": str(trace.resolve()),
        "size": st.st_size,
        "mtime_ns": st.st_mtime_ns,
        "importer_version": getattr(importer, "IMPORTER_VERSION", None),
        "max_wifi_age_s": max_wifi_age_s,
    }
    if importer.__name__.rsplit(".", 1)[-1] != "msindoor":
        key["importer"] = importer.__name__
    if import_kwargs:
        key["import_kwargs"] = json.loads(json.dumps(import_kwargs))
    if not reimport and log.is_file() and meta.is_file():
        try:
            cached = json.loads(meta.read_text(encoding="utf-8"))
            if cached.get("cache_key") == key:
                return cached
        except (OSError, ValueError):
            pass
    kwargs = dict(import_kwargs or {})
    if "max_wifi_age_s" in inspect.signature(importer.import_trace).parameters:
        kwargs["max_wifi_age_s"] = max_wifi_age_s
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", getattr(importer, "MalformedLineWarning", UserWarning))
        summary = importer.import_trace(trace, log, **kwargs)
    summary = dict(summary)
    summary.setdefault("out", str(log))
    summary["warnings"] = [str(w.message) for w in caught]
    summary["cache_key"] = key
    meta.write_text(json.dumps(json_ready(summary), indent=1) + "\n", encoding="utf-8")
    return summary


def prepare_walk(trace, out_dir, stridefixd, max_wifi_age_s: float = 3.0, reimport: bool = False) -> dict:
    """Import one trace (cached), replay it through ``stridefixd``, read STEP and TRUTH.

    Returns
    -------
    dict
        ``trace``, ``walk`` (the trace's stem), ``import`` (importer summary), ``error`` (None or the
        reason the walk could not be run), and when it ran: ``waypoint_t_us`` (w,), ``waypoint_xy_m``
        (w, 2), ``step_t_us`` (s,), ``step_range_mps2`` (s,), ``step_length_m`` (s,),
        ``health`` (last HEALTH fields), ``warnings``.
    """
    from stridefix_analyzer.datasets import msindoor

    trace, out_dir = Path(trace), Path(out_dir)
    walk = {"trace": str(trace), "walk": trace.stem, "import": None, "error": None, "warnings": []}
    cache_dir, fw_dir = out_dir / "cache", out_dir / "stridefixd"
    cache_dir.mkdir(parents=True, exist_ok=True)
    fw_dir.mkdir(parents=True, exist_ok=True)
    try:
        summary = _cached_import(trace, cache_dir, max_wifi_age_s, reimport)
    except (msindoor.TraceReadError, OSError) as exc:
        walk["error"] = f"import failed: {exc}"
        return walk
    walk["import"] = summary
    walk["warnings"] += summary.get("warnings", [])
    fw_log = fw_dir / f"{trace.stem}.lcmlog"
    cmd = [str(stridefixd), "--input", f"lcmlog:{summary['out']}", "--log", str(fw_log), "-q"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        walk["error"] = f"stridefixd exit {proc.returncode}: {' '.join(cmd)}: {proc.stderr.strip()[-500:]}"
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


# --- segments, calibration, scores -----------------------------------------------------------------


def build_segments(walks: list[dict], min_segment_m: float = DEFAULT_MIN_SEGMENT_M) -> Table:
    """One row per pair of consecutive waypoints of every walk.

    Returns
    -------
    Table
        ``walk`` (index into ``walks``), ``k`` (first waypoint), ``t0_us``, ``t1_us``, ``true_m``,
        ``weinberg`` (Σ range^¼ [(m/s²)^¼]), ``n_steps``, ``fw_length_m`` (Σ firmware length_m),
        ``speed_mps`` (true / duration), ``bad_range`` (steps with a non-finite or negative range),
        ``suspect`` (implied speed above :data:`SUSPECT_SPEED_MPS` or below
        :data:`SUSPECT_SLOW_MPS`), ``excluded`` ('' when
        scored, else the reason).
    """
    rows = []
    for w, walk in enumerate(walks):
        if walk.get("error") or "waypoint_t_us" not in walk:
            n_wp = walk["import"]["waypoints"] if walk.get("import") else 0
            for k in range(max(n_wp - 1, 0)):
                rows.append((w, k, 0, 0, math.nan, math.nan, 0, math.nan, math.nan, 0, False, "walk failed"))
            continue
        t_wp, xy = walk["waypoint_t_us"], walk["waypoint_xy_m"]
        t_st = walk["step_t_us"]
        rng = walk["step_range_mps2"]
        bad = ~np.isfinite(rng) | (rng < 0)
        root = np.where(bad, 0.0, np.abs(rng)) ** WEINBERG_EXPONENT
        imu0, imu1 = walk["import"].get("imu_t_first_us"), walk["import"].get("imu_t_last_us")
        tol = IMU_COVER_TOLERANCE_S * 1e6
        for k in range(len(t_wp) - 1):
            t0, t1 = int(t_wp[k]), int(t_wp[k + 1])
            true_m = float(np.hypot(*(xy[k + 1] - xy[k])))
            # steps with t0 < t <= t1
            i0, i1 = np.searchsorted(t_st, [t0, t1], side="right")
            duration_s = (t1 - t0) / 1e6
            speed = true_m / duration_s if duration_s > 0 else math.inf
            if imu0 is None or t0 < imu0 - tol or t1 > imu1 + tol:
                reason = "not covered by IMU data"
            elif t1 <= t0:
                reason = "zero duration"
            elif true_m < min_segment_m:
                reason = f"shorter than {min_segment_m:g} m"
            else:
                reason = ""
            rows.append(
                (
                    w,
                    k,
                    t0,
                    t1,
                    true_m,
                    float(root[i0:i1].sum()),
                    int(i1 - i0),
                    float(walk["step_length_m"][i0:i1].sum()),
                    speed,
                    int(bad[i0:i1].sum()),
                    bool(speed > SUSPECT_SPEED_MPS or speed < SUSPECT_SLOW_MPS),
                    reason,
                )
            )
    names = [
        "walk",
        "k",
        "t0_us",
        "t1_us",
        "true_m",
        "weinberg",
        "n_steps",
        "fw_length_m",
        "speed_mps",
        "bad_range",
        "suspect",
        "excluded",
    ]
    cols = list(zip(*rows)) if rows else [[] for _ in names]
    dtypes = [
        np.int64,
        np.int64,
        np.int64,
        np.int64,
        float,
        float,
        np.int64,
        float,
        float,
        np.int64,
        bool,
        object,
    ]
    return Table({n: np.asarray(c, dtype=t) for n, c, t in zip(names, cols, dtypes)})


def calibrate_lowo(seg_walk, true_m, weinberg, walks=None) -> np.ndarray:
    """Weinberg K per walk, leave one walk out.

    Parameters
    ----------
    seg_walk : (n,) int
        Walk of each (scored) segment.
    true_m : (n,) float
        True segment distances [m].
    weinberg : (n,) float
        Σ range^¼ of each segment's steps.
    walks : (m,) int, optional
        Walks to calibrate for (default: the distinct values of ``seg_walk``).

    Returns
    -------
    (m,) float
        K_i = Σ true / Σ weinberg over the segments of every walk except walk i [m/(m/s²)^¼];
        NaN when the other walks have no Weinberg sum.
    """
    seg_walk = np.asarray(seg_walk)
    true_m, weinberg = np.asarray(true_m, float), np.asarray(weinberg, float)
    walks = np.unique(seg_walk) if walks is None else np.asarray(walks)
    tot_true, tot_w = true_m.sum(), weinberg.sum()
    k = np.full(len(walks), math.nan)
    for j, w in enumerate(walks):
        mine = seg_walk == w
        den = tot_w - weinberg[mine].sum()
        if den > 0:
            k[j] = (tot_true - true_m[mine].sum()) / den
    return k


def stride_lowo(seg_walk, true_m, n_steps, walks=None) -> np.ndarray:
    """Fixed stride per walk, leave one walk out: median of true / n_steps over the other walks'
    segments with at least one step [m]; NaN when there is none."""
    seg_walk, n_steps = np.asarray(seg_walk), np.asarray(n_steps)
    true_m = np.asarray(true_m, float)
    walks = np.unique(seg_walk) if walks is None else np.asarray(walks)
    has = n_steps > 0
    stride = np.where(has, true_m / np.maximum(n_steps, 1), math.nan)
    out = np.full(len(walks), math.nan)
    for j, w in enumerate(walks):
        s = stride[has & (seg_walk != w)]
        if len(s):
            out[j] = float(np.median(s))
    return out


def error_stats(err_pct) -> dict:
    """n, mean, median, p75, p90, p95, max of absolute errors [%] (NaN-free input expected)."""
    e = np.abs(np.asarray(err_pct, float))
    e = e[np.isfinite(e)]
    if not len(e):
        return {"n": 0, **{k: math.nan for k in ("mean", "median", "p75", "p90", "p95", "max")}}
    p = np.percentile(e, [50, 75, 90, 95])
    return {
        "n": int(len(e)),
        "mean": float(e.mean()),
        "median": float(p[0]),
        "p75": float(p[1]),
        "p90": float(p[2]),
        "p95": float(p[3]),
        "max": float(e.max()),
    }


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


def _spread(values: np.ndarray) -> dict:
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if not len(v):
        return {"n": 0, "mean": math.nan, "std": math.nan, "min": math.nan, "max": math.nan}
    return {
        "n": int(len(v)),
        "mean": float(v.mean()),
        "std": float(v.std()),
        "min": float(v.min()),
        "max": float(v.max()),
    }


def _firmware_version(stridefixd: Path) -> str:
    try:
        return subprocess.run(
            [str(stridefixd), "-V"], capture_output=True, text=True, timeout=10
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError) as exc:
        return f"unknown ({exc})"


def run_pdr_distance(
    floor_dir,
    stridefixd=DEFAULT_STRIDEFIXD,
    out_dir=None,
    limit=None,
    min_segment_m: float = DEFAULT_MIN_SEGMENT_M,
    max_wifi_age_s: float = 3.0,
    jobs: int | None = None,
    reimport: bool = False,
    progress=None,
    plot: bool = True,
) -> dict:
    """Run the PDR distance benchmark on one floor; write JSON (+ PNG) into ``out_dir``.

    Returns the JSON document (a dict; non-finite numbers still as NaN).

    Raises
    ------
    RealbenchError
        No traces, or no executable ``stridefixd``.
    """
    t_start = time.perf_counter()
    label, traces = find_traces(floor_dir)
    if limit is not None:
        traces = traces[: max(int(limit), 0)]
    stridefixd = Path(stridefixd)
    if not (stridefixd.is_file() and os.access(stridefixd, os.X_OK)):
        raise RealbenchError(
            f"{stridefixd}: stridefixd not found or not executable (build it: cmake --build build)"
        )
    out_dir = Path(out_dir or os.path.join(DEFAULT_OUT, label.replace("/", "-")))
    out_dir.mkdir(parents=True, exist_ok=True)
    progress = progress or (lambda msg: None)
    jobs = max(1, jobs or os.cpu_count() or 1)
    walks: list[dict | None] = [None] * len(traces)
    with concurrent.futures.ProcessPoolExecutor(max_workers=jobs) as pool:
        futures = {
            pool.submit(prepare_walk, t, out_dir, stridefixd, max_wifi_age_s, reimport): i
            for i, t in enumerate(traces)
        }
        for done, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            i = futures[fut]
            walks[i] = fut.result()
            w = walks[i]
            state = w["error"] or (f"{len(w['step_t_us'])} steps, {len(w['waypoint_t_us'])} waypoints")
            progress(f"walk {done}/{len(traces)} {w['walk']}: {state}")

    seg, fits = score_segments(build_segments(walks, min_segment_m), len(walks))
    doc = summarize(label, floor_dir, walks, seg, fits, min_segment_m, max_wifi_age_s, limit)
    doc["stridefixd"] = {"path": str(stridefixd), "version": _firmware_version(stridefixd)}
    doc["out_dir"] = str(out_dir)
    doc["run_s"] = time.perf_counter() - t_start
    with open(out_dir / JSON_FILE, "w", encoding="utf-8") as f:
        json.dump(json_ready(doc), f, indent=1, allow_nan=False)
        f.write("\n")
    if plot:
        (out_dir / PNG_FILE).write_bytes(plot_pdr_distance(seg, label))
    return doc


def summarize(label, floor_dir, walks, seg: Table, fits: dict, min_segment_m, max_wifi_age_s, limit) -> dict:
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
            "K": {**_spread(k_scored), "all_walks": fits["K_all_walks"]},
        },
        "baseline_fixed_stride_lowo": {
            "abs_error_pct": error_stats(seg["baseline_err_pct"][used]),
            "signed_error_pct_median": _median(seg["baseline_err_pct"][used]),
            "stride_m": _spread(fits["stride_m"][scored_walks] if scored_walks else []),
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


def _median(x) -> float:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if len(x) else math.nan


def format_table(doc: dict) -> str:
    """A readable plain-text table of one floor's results."""

    def f(v, d=2):
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


# --- figure (no metrics computed here) -------------------------------------------------------------


def plot_pdr_distance(seg: Table, title: str) -> bytes:
    """PNG: PDR vs true segment distance (scatter, 1:1 and ±5 % lines) and the |error| CDFs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    used = seg["excluded"] == ""
    true = seg["true_m"][used]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5.2))
    ax1.scatter(true, seg["baseline_m"][used], s=9, color="0.6", label="fixed stride × steps")
    ax1.scatter(true, seg["pdr_m"][used], s=9, color="C0", label="Weinberg, K LOWO")
    top = float(np.nanmax(np.r_[true, seg["pdr_m"][used], 1.0])) * 1.05
    x = np.array([0, top])
    ax1.plot(x, x, "k-", lw=1, label="1:1")
    ax1.plot(x, 1.05 * x, "k:", lw=0.8, label="±5 %")
    ax1.plot(x, 0.95 * x, "k:", lw=0.8)
    ax1.set(
        xlim=(0, top),
        ylim=(0, top),
        xlabel="true segment distance [m]",
        ylabel="PDR distance [m]",
        title=f"{title}: {int(used.sum())} segments",
    )
    ax1.set_aspect("equal")
    ax1.legend(loc="upper left", fontsize=8)
    for col, name, color in (
        ("err_pct", "Weinberg, K LOWO", "C0"),
        ("baseline_err_pct", "fixed stride × steps", "0.5"),
        ("fw_err_pct", "firmware length_m", "C3"),
    ):
        e = np.sort(np.abs(seg[col][used]))
        e = e[np.isfinite(e)]
        if len(e):
            ax2.step(
                e,
                np.arange(1, len(e) + 1) / len(e),
                where="post",
                color=color,
                label=f"{name} (median {np.median(e):.1f} %)",
            )
    ax2.axvline(TARGET_MEDIAN_ABS_ERROR_PCT, color="k", ls=":", lw=0.8)
    ax2.axhline(0.5, color="k", ls=":", lw=0.8)
    ax2.set(
        xlim=(0, 50),
        ylim=(0, 1),
        xlabel="|distance error| [%]",
        ylabel="fraction of segments",
        title="error CDF",
    )
    ax2.grid(alpha=0.3)
    ax2.legend(loc="lower right", fontsize=8)
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


# --- CLI -------------------------------------------------------------------------------------------

BENCHES = ("fusion", "pdr-distance")


def with_default_bench(argv: list[str]) -> list[str]:
    """``stridefix realbench --format ...`` means ``stridefix realbench fusion --format ...``:
    insert the default benchmark when the word after ``realbench`` names none (and is no help)."""
    argv = list(argv)
    if argv and argv[0] == "realbench" and (len(argv) == 1 or argv[1] not in (*BENCHES, "-h", "--help")):
        argv.insert(1, "fusion")
    return argv


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare ``stridefix realbench`` and its benchmarks (``fusion`` is the default)."""
    p = subparsers.add_parser(
        "realbench",
        help="benchmarks of stridefixd on real public data (msindoor, gsd)",
        description="Benchmarks of the real firmware on real data sets. Without a benchmark name "
        "the fusion benchmark runs: stridefix realbench --format msindoor DIR [DIR...] "
        "--out results.json",
    )
    sub = p.add_subparsers(dest="bench", metavar="BENCH", required=True)
    from stridefix_analyzer.realbench.fusion import add_fusion_parser

    add_fusion_parser(sub)
    d = sub.add_parser(
        "pdr-distance",
        help="segment distance from steps + Weinberg length, K leave-one-walk-out",
        description="For every trace of a floor: import, replay through stridefixd, and compare "
        "the Weinberg distance (K calibrated leave-one-walk-out) between consecutive "
        "waypoints with the true straight-line distance. Writes "
        f"DIR/{JSON_FILE} and DIR/{PNG_FILE}.",
    )
    d.add_argument(
        "--floor",
        required=True,
        metavar="DIR",
        help="floor folder, e.g. ../shared/data/msindoor/site1/F2[/path_data_files]",
    )
    d.add_argument(
        "--stridefixd",
        default=os.environ.get("STRIDEFIXD", str(DEFAULT_STRIDEFIXD)),
        metavar="PATH",
        help="firmware binary (default: $STRIDEFIXD or build/firmware/stridefixd)",
    )
    d.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help=f"output and cache directory (default: {DEFAULT_OUT}/<site>-<floor>)",
    )
    d.add_argument(
        "--limit", type=int, default=None, metavar="N", help="only the first N traces (sorted by name)"
    )
    d.add_argument(
        "--min-segment-m",
        type=float,
        default=DEFAULT_MIN_SEGMENT_M,
        metavar="M",
        help=f"exclude shorter segments (default {DEFAULT_MIN_SEGMENT_M:g})",
    )
    d.add_argument(
        "--max-wifi-age-s",
        type=float,
        default=3.0,
        metavar="S",
        help="importer: drop cached Wi-Fi entries older than S (default 3)",
    )
    d.add_argument(
        "--jobs",
        "-j",
        type=int,
        default=None,
        metavar="N",
        help="walks prepared in parallel (default: CPU count)",
    )
    d.add_argument("--reimport", action="store_true", help="ignore the cached imported logs")
    d.set_defaults(_bench=_run_pdr_distance_cli)
    return p


def _run_pdr_distance_cli(args) -> int:
    def progress(msg):
        print(f"realbench: {msg}", file=sys.stderr, flush=True)

    try:
        doc = run_pdr_distance(
            args.floor,
            args.stridefixd,
            args.out,
            args.limit,
            args.min_segment_m,
            args.max_wifi_age_s,
            args.jobs,
            args.reimport,
            progress,
        )
    except RealbenchError as exc:
        print(f"stridefix realbench: error: {exc}", file=sys.stderr)
        return 2
    print(format_table(doc))
    print(
        f"wrote {os.path.join(doc['out_dir'], JSON_FILE)} and {os.path.join(doc['out_dir'], PNG_FILE)} "
        f"({doc['run_s']:.1f} s)"
    )
    return 0 if doc["segments"]["scored"] else 1


def run(args) -> int:
    """Entry point of ``stridefix realbench``."""
    return int(args._bench(args) or 0)
