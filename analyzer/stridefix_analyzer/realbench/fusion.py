"""``stridefix realbench --format msindoor|gsd DIR... --out results.json``: the fusion schemes on
real walks, leave one walk out.

Groups: msindoor — each DIR is a floor folder (``site1/F2``, or its ``path_data_files``); gsd — each
DIR holds GetSensorData logs (or is one), grouped by the building of their ground truth. Within a
group every walk is scored once, with everything the estimator may know taken from the *other* walks
of the group only (DESIGN.md, evaluation protocol):

1. every walk is imported (cached under ``OUT/cache/<group>``) and replayed through ``stridefixd``
   without a site (map rotation 0). From that replay and the walk's own files come its *per-walk
   sufficient statistics*: the walk-mode radio-map sums (:class:`~.radiomap.WalkStats`), the
   Weinberg segment sums of ``realbench pdr-distance``, the heading-offset sums of
   :func:`rotation_stats` and (gsd) the barometric height of each truth floor;
2. fold i = total − walk i: the site file (radio map in walk mode from the other walks' WIFI + TRUTH,
   floors and their heights, map rotation), the stride constant K (:func:`.realbench.calibrate_lowo`)
   and the map rotation (circular mean of STEP heading − truth direction over straight segments);
3. walk i is replayed with ``--site`` (all six schemes side by side) and ``--set stride.weinberg_k=K``
   and scored at its ground-truth times (``truth_source="waypoint"``, causal). Every scheme starts
   from the fixes. ``--true-start`` adds a run labelled truth-initialised (start at the first
   waypoint).

Floor heights (gsd): least squares over the other walks that visit two floors or more, of
``height(walk, floor) = H(floor) + offset(walk)``; floors without such evidence (or no multi-floor
walk at all) get :data:`DEFAULT_STOREY_M` per storey from the nearest known one. The JSON says which
(``floor_heights_source``). The firmware starts on ``init.floor`` (not on the floor of its first fix),
so on multi-floor sites the held-out walk is run twice: the first fix's floor of a first pass becomes
``init.floor`` of the scored pass (the start still comes from the fixes, never from the truth).

Outputs: ``results.json`` (per walk and per group, per scheme: n, mean, median, p75, p90, p95, max,
RMSE, floor hit rate, IPIN score = p75 of 2-D error + 15 m·|floor error|; the share of walks whose mean
error exceeds 15 m; the learned constants of every fold), the HTML report next to it
(:mod:`.realbench_report`), and the per-walk work files under ``OUT/realbench_work/<group>/<walk>``
(site file, stridefixd log, metrics.json, analysis.npz).
"""

from __future__ import annotations

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
from stridefix_analyzer.io.logread import LogReadError, LogTruncatedWarning, read_logs, read_table
from stridefix_analyzer.radiomap.build import WalkStats
from stridefix_analyzer.realbench import pdr_distance as rb
from stridefix_analyzer.realbench import select as rs

FORMATS = ("msindoor", "gsd")
SCHEME_ORDER = ("pdr_only", "wifi_only", "overwrite", "static", "adaptive", "kalman")
#: a walk whose mean error exceeds this is a failure for the robustness share [m]
ROBUST_MEAN_M = 15.0
#: IPIN competition score: p75 of (2-D error + this × |floor error|) [m per floor]
IPIN_FLOOR_PENALTY_M = 15.0
#: storey height when the other walks do not give one [m]
DEFAULT_STOREY_M = 4.0
#: rotation learning: shortest segment, smallest step-heading resultant length, fewest steps
ROT_MIN_SEGMENT_M = 4.0
ROT_MIN_RESULTANT = 0.95
ROT_MIN_STEPS = 3
DEFAULT_CELL_SIZE_M = 2.0
#: heading variants tried on the training walks of each fold: the one whose STEP headings agree best
#: with the truth directions (largest pooled resultant length of heading − direction) is used. Two
#: questions the firmware defaults answer for a body-worn board, not for every device: is the
#: gait-learned mounting offset better than a fixed one (a hand-held phone: no), and does a
#: magnetometer gate twice as wide keep more good samples than disturbed ones?
_WIDE_MAG_GATE = ["attitude.mag_field_tol_ut=16", "attitude.mag_dip_tol_deg=16"]
HEADING_VARIANTS = {
    "learned": [],
    "fixed": ["heading.learn_offset=0"],
    "learned, wide mag gate": _WIDE_MAG_GATE,
    "fixed, wide mag gate": ["heading.learn_offset=0"] + _WIDE_MAG_GATE,
}
#: 1: with the matcher's map levels averaged over all of a cell's scans (misses at fill), one detection
#: is already weak evidence, not noise to drop; 2 cost 2.4 m of Wi-Fi-only mean error on msindoor
DEFAULT_MIN_COUNT = 1
STATS_KEYS = ("n", "mean", "median", "p75", "p90", "p95", "max", "rmse")


class FusionBenchError(rb.RealbenchError):
    """The benchmark cannot run; the message says why."""


# --- inputs ----------------------------------------------------------------------------------------


def importer_module(fmt: str):
    """The importer of ``fmt`` (``stridefix_analyzer.datasets.<fmt>``)."""
    if fmt not in FORMATS:
        raise FusionBenchError(f"unknown format {fmt!r}; known: {', '.join(FORMATS)}")
    import importlib

    try:
        return importlib.import_module(f"stridefix_analyzer.datasets.{fmt}")
    except ImportError as exc:
        raise FusionBenchError(f"no importer for {fmt} (stridefix_analyzer.datasets.{fmt}: {exc})") from None


def find_groups(fmt: str, dirs) -> list[dict]:
    """Groups of traces before import: ``label``, ``traces`` (sorted paths), ``floor_dir``.

    msindoor: one group per floor folder. gsd: one group per DIR (regrouped by building after the
    import, see :func:`regroup_by_building`).
    """
    groups = []
    for d in dirs:
        d = Path(d)
        if fmt == "msindoor":
            label, traces = rb.find_traces(d)
            floor = traces[0].parent.parent
            groups.append({"label": label, "traces": traces, "floor_dir": floor})
        else:
            if d.is_file():
                traces = [d]
            elif d.is_dir():
                traces = sorted(p for p in d.glob("*.txt") if p.name.lower() != "readme.txt")
            else:
                raise FusionBenchError(f"{d}: no such file or directory")
            if not traces:
                raise FusionBenchError(f"{d}: no *.txt GetSensorData logs")
            origin = gsd_origin(traces[0])
            groups.append(
                {
                    "label": d.stem if d.is_file() else d.name,
                    "traces": traces,
                    "floor_dir": None,
                    "import_kwargs": {"origin": list(origin)} if origin else None,
                }
            )
    return groups


def gsd_origin(path) -> tuple[float, float] | None:
    """The first ``POSI`` latitude/longitude of a GetSensorData log [deg]: the common origin of the
    local metres of every walk of its folder (the importer's default origin is per file)."""
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("POSI;"):
                p = line.split(";")
                try:
                    return float(p[3]), float(p[4])
                except (IndexError, ValueError):
                    continue
    return None


def regroup_by_building(groups: list[dict], walks: list[dict]) -> list[dict]:
    """gsd: split each group by the building its import reports (``building`` / ``building_id``);
    walks without one stay in their DIR's group."""
    out = []
    for g in groups:
        by: dict[str, list[int]] = {}
        for i in g["walk_ids"]:
            imp = walks[i].get("import") or {}
            b = imp.get("building", imp.get("building_id"))
            by.setdefault(g["label"] if b is None else f"{g['label']}/building {b}", []).append(i)
        for label, ids in by.items():
            out.append({**g, "label": label, "walk_ids": ids})
    return out


# --- per-walk statistics ---------------------------------------------------------------------------


def rotation_stats(
    step_t_us,
    step_heading_rad,
    wp_t_us,
    wp_xy_m,
    min_segment_m: float = ROT_MIN_SEGMENT_M,
    min_resultant: float = ROT_MIN_RESULTANT,
    min_steps: int = ROT_MIN_STEPS,
) -> dict:
    """Sums of the heading offset (STEP heading − truth direction) over straight segments.

    A segment is two consecutive waypoints at least ``min_segment_m`` apart whose steps
    (t_k < t ≤ t_{k+1}) number ``min_steps`` or more and point the same way (resultant length of
    their unit heading vectors ≥ ``min_resultant``). Every step of such a segment adds
    ``(cos d, sin d)``, d = heading − atan2(Δy, Δx) of the segment.

    Returns
    -------
    dict
        ``sum_cos``, ``sum_sin``, ``n_steps``, ``n_segments`` (add over walks; the rotation is
        atan2(Σsin, Σcos) [rad]).
    """
    step_t_us, h = np.asarray(step_t_us, np.int64), np.asarray(step_heading_rad, float)
    wp_t_us, wp = np.asarray(wp_t_us, np.int64), np.asarray(wp_xy_m, float).reshape(-1, 2)
    out = {"sum_cos": 0.0, "sum_sin": 0.0, "n_steps": 0, "n_segments": 0}
    for k in range(len(wp_t_us) - 1):
        d = wp[k + 1] - wp[k]
        if not (np.hypot(*d) >= min_segment_m) or wp_t_us[k + 1] <= wp_t_us[k]:
            continue
        i0, i1 = np.searchsorted(step_t_us, [wp_t_us[k], wp_t_us[k + 1]], side="right")
        hs = h[i0:i1]
        hs = hs[np.isfinite(hs)]
        if len(hs) < min_steps or np.hypot(np.cos(hs).mean(), np.sin(hs).mean()) < min_resultant:
            continue
        off = hs - math.atan2(d[1], d[0])
        out["sum_cos"] += float(np.cos(off).sum())
        out["sum_sin"] += float(np.sin(off).sum())
        out["n_steps"] += int(len(hs))
        out["n_segments"] += 1
    return out


def learn_rotation_deg(stats: list[dict], exclude: int | None = None) -> float:
    """Map rotation [deg] (map heading = ENU heading − rotation) from the rotation sums of every
    walk but ``exclude``; NaN when none has a straight segment."""
    c = sum(s["sum_cos"] for j, s in enumerate(stats) if j != exclude)
    s_ = sum(s["sum_sin"] for j, s in enumerate(stats) if j != exclude)
    n = sum(s["n_steps"] for j, s in enumerate(stats) if j != exclude)
    return math.degrees(math.atan2(s_, c)) if n else math.nan


def heading_variants(param_sets) -> dict[str, list[str]]:
    """The heading variants to try: :data:`HEADING_VARIANTS`, or only the user's own choice when
    any of their keys is given with ``--set``."""
    return rs.variants_unless_given(param_sets, HEADING_VARIANTS)


def choose_heading_variant(per_walk: list[dict], exclude: int | None = None) -> tuple[str, dict]:
    """The variant whose STEP headings agree best with the truth directions over the walks but
    ``exclude``: the largest pooled mean resultant length of (heading − direction), i.e. the
    tightest heading error once the constant part (the map rotation) is taken out. Returns the name
    and the resultant length of every variant (NaN without straight segments)."""
    score = {}
    for name in per_walk[0]:
        c = sum(w[name]["sum_cos"] for j, w in enumerate(per_walk) if j != exclude)
        s_ = sum(w[name]["sum_sin"] for j, w in enumerate(per_walk) if j != exclude)
        n = sum(w[name]["n_steps"] for j, w in enumerate(per_walk) if j != exclude)
        score[name] = math.hypot(c, s_) / n if n else math.nan
    finite = {k: v for k, v in score.items() if math.isfinite(v)}
    best = max(finite, key=finite.get) if finite else next(iter(score))
    return best, score


def learn_heading(per_walk: list[dict], exclude: int | None = None) -> tuple[str, dict, float]:
    """:func:`choose_heading_variant` and the map rotation [deg] of that variant (NaN without
    straight segments), both from the walks but ``exclude``."""
    variant, score = choose_heading_variant(per_walk, exclude)
    return variant, score, learn_rotation_deg([r[variant] for r in per_walk], exclude)


def stride_k(seg: dict, mask) -> float:
    """Weinberg K of the segments in ``mask``: Σ true distance / Σ Weinberg sum (NaN when empty)."""
    w = seg["weinberg"][mask].sum()
    return float(seg["true_m"][mask].sum() / w) if w > 0 else math.nan


def pressure_to_height_m(pressure_pa):
    """Barometric height [m], the firmware's formula (sf_floor_pressure_to_height_m)."""
    return 44330.77 * (1.0 - (np.asarray(pressure_pa, float) / 101325.0) ** 0.190263)


def floor_heights_of_walk(
    baro_t_us, pressure_pa, truth_t_us, truth_floor, window_s: float = 2.0
) -> dict[int, float]:
    """Median barometric height [m] per truth floor: baro samples within ``window_s`` of each truth
    sample, pooled per floor."""
    baro_t_us, truth_t_us = np.asarray(baro_t_us, np.int64), np.asarray(truth_t_us, np.int64)
    if not len(baro_t_us) or not len(truth_t_us):
        return {}
    h = pressure_to_height_m(pressure_pa)
    per: dict[int, list] = {}
    w = int(window_s * 1e6)
    for t, f in zip(truth_t_us, np.asarray(truth_floor, np.int64)):
        i0, i1 = np.searchsorted(baro_t_us, [t - w, t + w])
        if i1 > i0:
            per.setdefault(int(f), []).append(h[i0:i1])
    return {f: float(np.median(np.concatenate(v))) for f, v in per.items()}


def learn_floor_heights(
    per_walk: list[dict[int, float]], floors: list[int], storey_m: float = DEFAULT_STOREY_M
) -> tuple[list[float], str]:
    """Heights [m] of ``floors`` (consecutive, ascending) from per-walk floor heights.

    Least squares of h(w, f) = H(f) + c_w over walks that saw two floors or more, H(lowest known) = 0;
    floors without evidence: ``storey_m`` per storey from the nearest known floor. Returns
    (heights, source) where source is ``"barometer"``, ``"barometer+default"`` or ``"default"``.
    """
    multi = [w for w in per_walk if len(w) >= 2]
    known: dict[int, float] = {}
    if multi:
        fl = sorted({f for w in multi for f in w})
        idx = {f: i for i, f in enumerate(fl)}
        rows, rhs = [], []
        nf, nw = len(fl), len(multi)
        for j, w in enumerate(multi):
            for f, h in w.items():
                r = np.zeros(nf + nw)
                r[idx[f]], r[nf + j] = 1.0, 1.0
                rows.append(r), rhs.append(h)
        r = np.zeros(nf + nw)
        r[0] = 1.0
        rows.append(r), rhs.append(0.0)
        sol = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
        # only floors connected to floor fl[0] through multi-floor walks are meaningful; with one
        # or two multi-floor walks sharing floors that holds; check monotony below anyway
        known = {f: float(sol[idx[f]]) for f in fl}
    heights, used_default = [], False
    for f in floors:
        if f in known:
            heights.append(known[f])
        elif known:
            near = min(known, key=lambda k: abs(k - f))
            heights.append(known[near] + (f - near) * storey_m)
            used_default = True
        else:
            heights.append(f * storey_m)
            used_default = True
    if any(not b > a for a, b in zip(heights, heights[1:])):
        return [f * storey_m for f in floors], "default (barometer heights not increasing)"
    src = "default" if not known else ("barometer+default" if used_default else "barometer")
    return heights, src


def prepare(
    trace,
    fmt: str,
    work_dir,
    cache_dir,
    stridefixd,
    max_wifi_age_s: float | None = None,
    reimport: bool = False,
    cell_size_m: float = DEFAULT_CELL_SIZE_M,
    import_kwargs: dict | None = None,
    param_sets: list[str] | None = None,
) -> dict:
    """Phase 1 of one walk: import (cached), replay without a site, and its sufficient statistics.

    Returns
    -------
    dict
        The keys :func:`.realbench.build_segments` reads (``walk``, ``import``, ``error``,
        ``waypoint_t_us``, ``waypoint_xy_m``, ``step_t_us``, ``step_range_mps2``,
        ``step_length_m``), plus ``stats`` (:class:`~.radiomap.WalkStats`), ``rotation``
        (:func:`rotation_stats`), ``floor_heights`` (:func:`floor_heights_of_walk`), ``floors``
        (truth floors), ``first_waypoint`` (t_us, x, y, floor) and ``import_log``.
    """
    from stridefix_analyzer.radiomap.build import RadioMapInputError, WalkStats, load_recordings

    importer = importer_module(fmt)
    if max_wifi_age_s is None:
        max_wifi_age_s = getattr(importer, "DEFAULT_MAX_WIFI_AGE_S", 3.0)
    trace = Path(trace)
    walk = {"trace": str(trace), "walk": trace.stem, "import": None, "error": None, "warnings": []}
    cache_dir, fw_dir = Path(cache_dir), Path(work_dir) / "nosite"
    cache_dir.mkdir(parents=True, exist_ok=True)
    fw_dir.mkdir(parents=True, exist_ok=True)
    try:
        summary = rb._cached_import(trace, cache_dir, max_wifi_age_s, reimport, importer, import_kwargs)
    except Exception as exc:  # any importer failure loses this walk only
        walk["error"] = f"import failed: {type(exc).__name__}: {exc}"
        return walk
    walk["import"] = summary
    walk["import_log"] = imp = summary["out"]
    walk["warnings"] += summary.get("warnings", [])[:5]
    variants = heading_variants(param_sets)
    headings = {}
    for name, sets in variants.items():  # the first variant's STEP stream also gives K and steps
        fw_log = fw_dir / f"{trace.stem}.{name}.lcmlog"
        cmd = [str(stridefixd), "--input", f"lcmlog:{imp}", "--log", str(fw_log), "-q"]
        cmd += [a for kv in list(param_sets or []) + sets for a in ("--set", kv)]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            walk["error"] = f"stridefixd exit {proc.returncode}: {proc.stderr.strip()[-300:]}"
            return walk
        if name != next(iter(variants)):
            st = read_table(fw_log, "STEP")
            headings[name] = (st["t_us"], st["heading_rad"]) if st is not None else None
    fw_log = fw_dir / f"{trace.stem}.{next(iter(variants))}.lcmlog"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)
            fw = read_logs([fw_log], decode=("STEP",))
            raw = read_logs(
                [imp],
                decode=("TRUTH", "BARO", "IMU") if "imu_t_first_us" not in summary else ("TRUTH", "BARO"),
            )
        recs = load_recordings([imp])
    except (LogReadError, RadioMapInputError) as exc:
        walk["error"] = f"cannot read logs: {exc}"
        return walk
    truth, steps, baro = raw.table("TRUTH"), fw.table("STEP"), raw.table("BARO")
    if truth is None or not len(truth):
        walk["error"] = "no TRUTH in the imported log"
        return walk
    if "imu_t_first_us" not in summary:
        imu = raw.table("IMU")
        summary["imu_t_first_us"] = int(imu["t_us"][0]) if imu is not None and len(imu) else None
        summary["imu_t_last_us"] = int(imu["t_us"][-1]) if imu is not None and len(imu) else None
    summary.setdefault("waypoints", len(truth))
    walk["waypoint_t_us"] = truth["t_us"]
    walk["waypoint_xy_m"] = np.column_stack([truth["x_m"], truth["y_m"]])
    walk["waypoint_floor"] = truth["floor"].astype(np.int64)
    z = np.zeros(0)
    walk["step_t_us"] = steps["t_us"] if steps is not None else np.zeros(0, np.int64)
    walk["step_range_mps2"] = steps["accel_range_mps2"] if steps is not None else z
    walk["step_length_m"] = steps["length_m"] if steps is not None else z
    walk["step_heading_rad"] = steps["heading_rad"] if steps is not None else z
    walk["stats"] = WalkStats.from_recordings(recs, cell_size_m=cell_size_m)
    walk["rotation"] = {
        next(iter(variants)): rotation_stats(
            walk["step_t_us"], walk["step_heading_rad"], walk["waypoint_t_us"], walk["waypoint_xy_m"]
        )
    }
    for name, th in headings.items():
        walk["rotation"][name] = rotation_stats(
            th[0] if th else [], th[1] if th else [], walk["waypoint_t_us"], walk["waypoint_xy_m"]
        )
    walk["floor_heights"] = (
        floor_heights_of_walk(baro["t_us"], baro["pressure_pa"], truth["t_us"], truth["floor"])
        if baro is not None and len(baro)
        else {}
    )
    walk["floors"] = sorted({int(f) for f in truth["floor"]})
    walk["first_waypoint"] = (
        int(truth["t_us"][0]),
        float(truth["x_m"][0]),
        float(truth["y_m"][0]),
        int(truth["floor"][0]),
    )
    return walk


# --- folds -----------------------------------------------------------------------------------------

_STATE: dict = {}


def _init_worker(state: dict) -> None:
    _STATE.clear()
    _STATE.update(state)


def fold_site(
    total,
    held,
    *,
    name: str,
    rotation_deg: float,
    floor_heights_m,
    lowest_floor,
    min_count: int = DEFAULT_MIN_COUNT,
):
    """The fold's site: radio map of ``total − held`` (sufficient statistics) with the given
    rotation and floors; returns (site, summary)."""
    stats = total - held
    return stats.to_site(
        min_count=min_count,
        name=name,
        map_rotation_deg=rotation_deg,
        floor_heights_m=floor_heights_m,
        lowest_floor=lowest_floor,
        source=f"stridefix realbench: leave-one-walk-out fold without {name}",
    )


def _first_fix_floor(fw_log: Path) -> int | None:
    fix = read_table(fw_log, "FIX")
    if fix is None or not len(fix):
        return None
    ok = fix["n_ap_used"] > 0
    return int(fix["floor"][ok][0]) if ok.any() else None


def run_fold(job: dict) -> dict:
    """Phase 3 of one walk: write its fold's site, replay it with ``--site``, score every scheme."""
    from stridefix_analyzer.io.sitefile import write_site
    from stridefix_analyzer.radiomap.build import RadioMapInputError
    from stridefix_analyzer.scoring.analyze import run_analyze
    from stridefix_analyzer.scoring.metrics import MetricsInputError

    t0 = time.perf_counter()
    out = {"walk": job["walk"], "group": job["group"], "error": None, "fold": {}}
    wdir = Path(job["dir"])
    wdir.mkdir(parents=True, exist_ok=True)
    total, held = _STATE["total"][job["group"]], _STATE["stats"][job["index"]]
    try:
        site, summ = fold_site(
            total,
            held,
            name=job["walk"],
            rotation_deg=job["rotation_deg"],
            floor_heights_m=job["floor_heights_m"],
            lowest_floor=job["lowest_floor"],
            min_count=job["min_count"],
        )
    except RadioMapInputError as exc:
        out["error"] = f"no site for this fold: {exc}"
        return out
    site_path = wdir / "site.sfsite"
    write_site(site_path, site)
    out["fold"] = {
        "K": job["K"],
        "rotation_deg": job["rotation_deg"],
        "heading_variant": job.get("heading_variant"),
        "matcher_variant": job.get("matcher_variant"),
        "adaptive_variant": job.get("adaptive_variant"),
        "heading_resultant": job.get("heading_resultant"),
        "n_rp": site.n_rp,
        "n_ap": site.n_ap,
        "n_entries": site.n_entries,
        "n_floors": site.n_floors,
        "lowest_floor": site.lowest_floor,
        "floor_heights_m": [float(h) for h in site.floor_height_m],
        "floor_heights_source": job["floor_heights_source"],
        "scans_used": summ["scans"].get("used"),
    }
    sets = [a for kv in job.get("param_sets", []) for a in ("--set", kv)]
    if math.isfinite(job["K"]):
        sets += ["--set", f"stride.weinberg_k={job['K']:.6f}"]
    base = [job["stridefixd"], "--input", f"lcmlog:{job['import_log']}", "--site", str(site_path), "-q"]
    runs = [("fixes", [])]
    if job.get("true_start"):
        t, x, y, f = job["first_waypoint"]
        runs.append(
            (
                "true_start",
                [
                    "--set",
                    "init.use_config_pose=1",
                    "--set",
                    f"init.x_m={x:.3f}",
                    "--set",
                    f"init.y_m={y:.3f}",
                    "--set",
                    f"init.floor={f}",
                ],
            )
        )
    for tag, extra in runs:
        fw_log = wdir / ("stridefixd.lcmlog" if tag == "fixes" else f"stridefixd_{tag}.lcmlog")
        cmd = base + sets + extra + ["--log", str(fw_log)]
        if tag == "fixes" and site.n_floors > 1:
            # the firmware starts on init.floor: take the first fix's floor from a first pass
            proc = subprocess.run(cmd, capture_output=True, text=True)
            f0 = _first_fix_floor(fw_log) if proc.returncode == 0 else None
            if f0 is not None:
                cmd = cmd[:-2] + ["--set", f"init.floor={f0}", "--log", str(fw_log)]
                out["fold"]["init_floor_from_first_fix"] = f0
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            out["error"] = f"stridefixd exit {proc.returncode}: {proc.stderr.strip()[-300:]}"
            return out
        adir = wdir if tag == "fixes" else wdir / tag
        label = f"{job['walk']}: leave-one-walk-out, " + (
            "every scheme from its first fix" if tag == "fixes" else "truth-initialised"
        )
        try:
            try:
                _, metrics = run_analyze(
                    [str(fw_log), job["import_log"]], str(adir), label=label, truth_source="waypoint"
                )
            except MetricsInputError as exc:
                if "source" not in str(exc):
                    raise
                _, metrics = run_analyze([str(fw_log), job["import_log"]], str(adir), label=label)
        except (LogReadError, MetricsInputError) as exc:
            out["error"] = f"cannot score: {exc}"
            return out
        out[tag] = score_walk(metrics)
    out["run_s"] = time.perf_counter() - t0
    return out


def score_walk(metrics) -> dict:
    """Per scheme of one walk: stats, floor hit rate, IPIN score and the raw per-sample errors."""
    res = {}
    for s in metrics.schemes.values():
        m = s.match
        sc = m["scored"]
        err = m["error_m"][sc]
        ferr = np.abs(m["pose_floor"][sc] - m["truth_floor"][sc]).astype(float)
        res[s.name] = {
            **{k: s.summary["position_error_m"][k] for k in STATS_KEYS},
            "unscored": s.summary["unscored"],
            "floor_hit_rate": s.summary["floor_hit_rate"],
            "ipin_score": ipin_score(err, ferr),
            "errors_m": err.astype(float).tolist(),
            "floor_errors": ferr.astype(int).tolist(),
        }
    return res


def ipin_score(error_m, floor_error) -> float:
    """IPIN score [m]: 75th percentile of 2-D error + :data:`IPIN_FLOOR_PENALTY_M` × |floor error|."""
    e = np.asarray(error_m, float) + IPIN_FLOOR_PENALTY_M * np.abs(np.asarray(floor_error, float))
    e = e[np.isfinite(e)]
    return float(np.percentile(e, 75)) if len(e) else math.nan


def stats_of(errors) -> dict:
    e = np.asarray(errors, float)
    e = e[np.isfinite(e)]
    if not len(e):
        return {"n": 0, **{k: math.nan for k in STATS_KEYS[1:]}}
    p = np.percentile(e, [50, 75, 90, 95])
    return {
        "n": int(len(e)),
        "mean": float(e.mean()),
        "median": float(p[0]),
        "p75": float(p[1]),
        "p90": float(p[2]),
        "p95": float(p[3]),
        "max": float(e.max()),
        "rmse": float(np.sqrt(np.mean(e**2))),
    }


def summarize_group(results: list[dict], tag: str = "fixes") -> dict:
    """Per scheme over a group's walks: pooled sample stats, IPIN score, floor hit rate, the
    per-walk mean spread and the share of walks whose mean error exceeds :data:`ROBUST_MEAN_M`."""
    table = {}
    names = [n for n in SCHEME_ORDER if any(n in r.get(tag, {}) for r in results)]
    for name in names:
        rows = [r[tag][name] for r in results if name in r.get(tag, {})]
        err = np.concatenate([np.asarray(r["errors_m"], float) for r in rows]) if rows else []
        ferr = np.concatenate([np.asarray(r["floor_errors"], float) for r in rows]) if rows else []
        means = np.array([r["mean"] for r in rows], float)
        finite = means[np.isfinite(means)]
        table[name] = {
            **stats_of(err),
            "ipin_score": ipin_score(err, ferr),
            "floor_hit_rate": float(np.mean(ferr == 0)) if len(ferr) else math.nan,
            "walks": len(rows),
            "walks_mean_over_15m": int(np.sum(finite > ROBUST_MEAN_M)),
            "share_walks_mean_over_15m": (
                float(np.mean(finite > ROBUST_MEAN_M)) if len(finite) else math.nan
            ),
            "walk_mean_median": float(np.median(finite)) if len(finite) else math.nan,
        }
    w, a = table.get("wifi_only", {}).get("mean"), table.get("adaptive", {}).get("mean")
    red = 100.0 * (w - a) / w if w and a is not None and math.isfinite(w) and w > 0 else math.nan
    return {"schemes": table, "adaptive_vs_wifi_only_reduction_pct": red}


# --- the benchmark ---------------------------------------------------------------------------------


class _Progress:
    def __init__(self, what: str, n: int, stream=sys.stderr):
        self.what, self.n, self.t0, self.i, self.stream = what, n, time.perf_counter(), 0, stream

    def step(self, note: str = "") -> None:
        self.i += 1
        el = time.perf_counter() - self.t0
        eta = el / self.i * (self.n - self.i)
        print(
            f"realbench: {self.what} [{self.i}/{self.n}] {note}  elapsed {el:.0f} s, ETA {eta:.0f} s",
            file=self.stream,
            flush=True,
        )


def run_fusion(
    fmt: str,
    dirs,
    out_json,
    stridefixd=rb.DEFAULT_STRIDEFIXD,
    limit=None,
    jobs: int = 2,
    reimport: bool = False,
    true_start: bool = False,
    max_wifi_age_s: float | None = None,
    cell_size_m: float = DEFAULT_CELL_SIZE_M,
    min_count: int = DEFAULT_MIN_COUNT,
    cache_dir=None,
    report: bool = True,
    quiet: bool = False,
    param_sets: list[str] | None = None,
) -> dict:
    """Run the leave-one-walk-out fusion benchmark; write ``out_json`` (+ the HTML report).

    Returns the JSON document (non-finite numbers still NaN).
    """
    t_start = time.perf_counter()
    stridefixd = Path(stridefixd)
    if not (stridefixd.is_file() and os.access(stridefixd, os.X_OK)):
        raise FusionBenchError(
            f"{stridefixd}: stridefixd not found or not executable (build it: cmake --build build)"
        )
    if param_sets:  # a bad KEY=VALUE fails here once, not in every fold
        probe = subprocess.run(
            [str(stridefixd), "--print-config"] + [a for kv in param_sets for a in ("--set", kv)],
            capture_output=True,
            text=True,
        )
        if probe.returncode != 0:
            raise FusionBenchError(f"--set: {probe.stderr.strip()[-300:]}")
    if max_wifi_age_s is None:
        max_wifi_age_s = getattr(importer_module(fmt), "DEFAULT_MAX_WIFI_AGE_S", 3.0)
    out_json = Path(out_json)
    out_dir = out_json.parent if str(out_json.parent) else Path(".")
    out_dir.mkdir(parents=True, exist_ok=True)
    groups = find_groups(fmt, dirs)
    if limit is not None:
        for g in groups:
            g["traces"] = g["traces"][: max(int(limit), 0)]
    stream = open(os.devnull, "w") if quiet else sys.stderr
    # phase 1: import, replay without a site, per-walk statistics
    tasks = []
    for g in groups:
        safe = g["label"].replace("/", "-")
        g["cache"] = Path(cache_dir) / safe if cache_dir else out_dir / "cache" / safe
        g["work"] = out_dir / "realbench_work" / safe
        g["walk_ids"] = []
        for tr in g["traces"]:
            g["walk_ids"].append(len(tasks))
            tasks.append((tr, g))
    walks: list[dict | None] = [None] * len(tasks)
    prog = _Progress("prepare", len(tasks), stream)
    with concurrent.futures.ProcessPoolExecutor(max_workers=max(1, jobs)) as pool:
        futs = {
            pool.submit(
                prepare,
                tr,
                fmt,
                g["work"],
                g["cache"],
                stridefixd,
                max_wifi_age_s,
                reimport,
                cell_size_m,
                g.get("import_kwargs"),
                param_sets,
            ): i
            for i, (tr, g) in enumerate(tasks)
        }
        for fut in concurrent.futures.as_completed(futs):
            i = futs[fut]
            walks[i] = fut.result()
            w = walks[i]
            prog.step(
                f"{w['walk']}: "
                + (w["error"] or f"{len(w['step_t_us'])} steps, {len(w['waypoint_t_us'])} waypoints")
            )
    t_prep = time.perf_counter() - t_start
    if fmt == "gsd":
        groups = regroup_by_building(groups, walks)
    # phase 2: the constants of every fold
    fold_jobs, totals, group_info = [], {}, {}
    for g in groups:
        ok = [i for i in g["walk_ids"] if not walks[i]["error"]]
        info = {
            "label": g["label"],
            "walks": len(g["walk_ids"]),
            "ran": len(ok),
            "failed": [
                {"walk": walks[i]["walk"], "error": walks[i]["error"]}
                for i in g["walk_ids"]
                if walks[i]["error"]
            ],
            "floor_dir": str(g["floor_dir"]) if g["floor_dir"] else None,
        }
        group_info[g["label"]] = info
        if not ok:
            continue
        sub = [walks[i] for i in ok]
        seg = rb.build_segments(sub)
        used = seg["excluded"] == ""
        ks = rb.calibrate_lowo(
            seg["walk"][used], seg["true_m"][used], seg["weinberg"][used], np.arange(len(sub))
        )
        total = WalkStats.total([w["stats"] for w in sub])
        totals[g["label"]] = total
        rot_stats = [w["rotation"] for w in sub]
        info["K_all_walks"] = stride_k(seg, used)
        (
            info["heading_variant_all_walks"],
            info["heading_resultant_all_walks"],
            info["rotation_all_walks_deg"],
        ) = learn_heading(rot_stats)
        candidates = rs.matcher_variants(param_sets)
        sel_prog = _Progress("choose matcher", rs.n_tasks(len(sub), len(candidates)), stream)

        built_sites: dict[str, list[str]] = {}

        def build_site(
            removed,
            others,
            name,
            path,
            total=total,
            sub=sub,
            seg=seg,
            used=used,
            rot_stats=rot_stats,
            built=built_sites,
        ):
            """A selection site and the settings learned with it, from ``others`` only. Both
            selection stages use the same block pairs: each site is written once."""
            if str(path) in built:
                return built[str(path)]
            from stridefix_analyzer.io.sitefile import write_site

            idx = [j for j, w in enumerate(sub) if any(w is o for o in others)]
            heights, _, lowest = fold_floors(others, [])
            variant, _, rot = learn_heading([rot_stats[j] for j in idx])
            write_site(
                path,
                fold_site(
                    total,
                    removed,
                    name=name,
                    rotation_deg=rot if math.isfinite(rot) else 0.0,
                    floor_heights_m=heights,
                    lowest_floor=lowest,
                    min_count=min_count,
                )[0],
            )
            k = stride_k(seg, used & np.isin(seg["walk"], idx))
            built[str(path)] = heading_variants(param_sets)[variant] + (
                [f"stride.weinberg_k={k:.6f}"] if math.isfinite(k) else []
            )
            return built[str(path)]

        matcher, info["matcher_selection"] = rs.select(
            sub,
            build_site,
            stridefixd=stridefixd,
            work_dir=g["work"] / "select",
            base_sets=list(param_sets or []),
            candidates=candidates,
            jobs=jobs,
            progress=sel_prog.step,
        )
        adaptive_cands = rs.adaptive_variants(param_sets)
        ad_prog = _Progress("choose adaptive", rs.n_tasks(len(sub), len(adaptive_cands)), stream)
        chosen = info["matcher_selection"].get("choice_of_block", {})
        adaptive, info["adaptive_selection"] = rs.select(
            sub,
            build_site,
            stridefixd=stridefixd,
            work_dir=g["work"] / "select",
            base_sets=list(param_sets or []),
            candidates=adaptive_cands,
            jobs=jobs,
            progress=ad_prog.step,
            stage="adaptive",
            block_sets={a: candidates[n] for a, n in chosen.items()},
        )
        for j, i in enumerate(ok):
            others = [w for jj, w in enumerate(sub) if jj != j]
            variant, variant_score, rot = learn_heading(rot_stats, exclude=j)
            heights, src, lowest = fold_floors(others, sub[j]["floors"])
            fold_jobs.append(
                {
                    "index": i,
                    "walk": walks[i]["walk"],
                    "group": g["label"],
                    "dir": str(g["work"] / walks[i]["walk"]),
                    "import_log": walks[i]["import_log"],
                    "stridefixd": str(stridefixd),
                    "K": float(ks[j]),
                    "rotation_deg": 0.0 if not math.isfinite(rot) else rot,
                    "rotation_learned": math.isfinite(rot),
                    "floor_heights_m": heights,
                    "floor_heights_source": src,
                    "lowest_floor": lowest,
                    "min_count": min_count,
                    "true_start": true_start,
                    "param_sets": list(param_sets or [])
                    + heading_variants(param_sets)[variant]
                    + candidates[matcher[j]]
                    + adaptive_cands[adaptive[j]],
                    "heading_variant": variant,
                    "heading_resultant": variant_score,
                    "matcher_variant": matcher[j],
                    "adaptive_variant": adaptive[j],
                    "first_waypoint": walks[i]["first_waypoint"],
                }
            )
    # phase 3: the folds, in parallel
    state = {
        "total": totals,
        "stats": {i: walks[i]["stats"] for i in range(len(walks)) if not walks[i]["error"]},
    }
    results = []
    prog = _Progress("fold", len(fold_jobs), stream)
    t3 = time.perf_counter()
    with concurrent.futures.ProcessPoolExecutor(
        max_workers=max(1, jobs), initializer=_init_worker, initargs=(state,)
    ) as pool:
        futs = [pool.submit(run_fold, j) for j in fold_jobs]
        for fut in concurrent.futures.as_completed(futs):
            r = fut.result()
            results.append(r)
            k = r.get("fixes", {}).get("kalman", {}).get("mean")
            prog.step(
                f"{r['walk']}: " + (r["error"] or (f"kalman mean {k:.1f} m" if k is not None else "scored"))
            )
    order = {j["walk"]: n for n, j in enumerate(fold_jobs)}
    results.sort(key=lambda r: order[r["walk"]])
    job_of = {j["walk"]: j for j in fold_jobs}
    doc = build_doc(fmt, dirs, groups, group_info, walks, results, job_of, limit, true_start)
    doc["params"] = {
        "cell_size_m": cell_size_m,
        "min_count": min_count,
        "firmware_sets": list(param_sets or []),
        "max_wifi_age_s": max_wifi_age_s,
        "limit": limit,
        "jobs": jobs,
        "robust_mean_m": ROBUST_MEAN_M,
        "ipin_floor_penalty_m": IPIN_FLOOR_PENALTY_M,
        "rotation": {
            "min_segment_m": ROT_MIN_SEGMENT_M,
            "min_resultant": ROT_MIN_RESULTANT,
            "min_steps": ROT_MIN_STEPS,
        },
        "default_storey_m": DEFAULT_STOREY_M,
    }
    doc["stridefixd"] = {"path": str(stridefixd), "version": rb._firmware_version(stridefixd)}
    doc["run_s"] = {
        "prepare": t_prep,
        "folds": time.perf_counter() - t3,
        "total": time.perf_counter() - t_start,
    }
    if report:
        from stridefix_analyzer.realbench.report import write_report

        html = out_json.with_suffix(".html")
        write_report(doc, html)
        doc["report"] = str(html)
    doc["run_s"]["total"] = time.perf_counter() - t_start
    with open(out_json, "w", encoding="utf-8") as f:
        json.dump(json_ready(_strip_samples(doc)), f, indent=1, allow_nan=False)
        f.write("\n")
    if quiet:
        stream.close()
    return doc


def fold_floors(others: list[dict], own_floors) -> tuple[list[float], str, int]:
    """Floor heights [m], their source and the lowest floor for a site learned from ``others``
    (the floors they visit, or ``own_floors`` when they carry none)."""
    floors = sorted({f for w in others for f in w["floors"]}) or sorted(own_floors)
    fl = list(range(floors[0], floors[-1] + 1))
    if len(fl) > 1:
        heights, src = learn_floor_heights([w["floor_heights"] for w in others], fl)
    else:
        heights, src = [fl[0] * rb_default_height()], "single floor"
    return heights, src, fl[0]


def rb_default_height() -> float:
    """Storey height of a one-floor site [m] (the radio map's default; only its index matters)."""
    from stridefix_analyzer.radiomap.build import DEFAULT_FLOOR_HEIGHT_M

    return DEFAULT_FLOOR_HEIGHT_M


def build_doc(fmt, dirs, groups, group_info, walks, results, job_of, limit, true_start) -> dict:
    per_group = []
    for g in groups:
        info = group_info[g["label"]]
        rs = [r for r in results if r["group"] == g["label"]]
        entry = {**info, "summary": summarize_group([r for r in rs if not r["error"]], "fixes")}
        if true_start:
            entry["summary_true_start"] = summarize_group([r for r in rs if not r["error"]], "true_start")
        entry["fold_errors"] = [{"walk": r["walk"], "error": r["error"]} for r in rs if r["error"]]
        folds = [r["fold"] for r in rs if r.get("fold")]
        entry["constants"] = {
            "K": _spread([f["K"] for f in folds]),
            "rotation_deg": _spread([f["rotation_deg"] for f in folds]),
            "n_rp": _spread([f["n_rp"] for f in folds]),
            "n_ap": _spread([f["n_ap"] for f in folds]),
            **{
                key: {
                    v: sum(1 for f in folds if f.get(key) == v)
                    for v in sorted({f.get(key) for f in folds} - {None})
                }
                for key in ("heading_variant", "matcher_variant", "adaptive_variant")
            },
        }
        entry["walk_rows"] = []
        for r in rs:
            j = job_of[r["walk"]]
            w = walks[j["index"]]
            row = {
                "walk": r["walk"],
                "error": r["error"],
                "fold": r.get("fold"),
                "rotation_learned": j["rotation_learned"],
                "waypoints": len(w["waypoint_t_us"]),
                "steps_nosite": len(w["step_t_us"]),
                "duration_s": (w["import"] or {}).get("duration_s"),
                "floors": w["floors"],
                "dir": j["dir"],
            }
            for tag in ("fixes", "true_start"):
                if tag in r:
                    row[tag] = r[tag]
            entry["walk_rows"].append(row)
        per_group.append(entry)
    return {
        "benchmark": "realbench fusion (leave one walk out)",
        "format": fmt,
        "inputs": [str(d) for d in dirs],
        "true_start": true_start,
        "groups": per_group,
    }


def _spread(v) -> dict:
    v = np.asarray([x for x in v if x is not None], float)
    v = v[np.isfinite(v)]
    if not len(v):
        return {"n": 0, "mean": math.nan, "min": math.nan, "max": math.nan, "std": math.nan}
    return {
        "n": int(len(v)),
        "mean": float(v.mean()),
        "min": float(v.min()),
        "max": float(v.max()),
        "std": float(v.std()),
    }


def _strip_samples(doc: dict) -> dict:
    """The JSON keeps per-walk statistics; per-sample errors stay in each walk's analysis.npz."""
    out = json.loads(json.dumps(json_ready(doc)))
    for g in out["groups"]:
        for row in g["walk_rows"]:
            for tag in ("fixes", "true_start"):
                for s in (row.get(tag) or {}).values():
                    s.pop("errors_m", None)
                    s.pop("floor_errors", None)
    return out


# --- console ---------------------------------------------------------------------------------------


def format_tables(doc: dict) -> str:
    """Per group: scheme × n, mean, median, p75, p90, max, RMSE, IPIN, floor %, walks > 15 m."""

    def f(v, d=2):
        return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{d}f}"

    lines = []
    for g in doc["groups"]:
        c = g["constants"]
        lines.append(
            f"{g['label']}: {g['walks']} walks ({g['ran']} ran, "
            f"{len(g['walk_rows']) - len(g['fold_errors'])} scored), leave one walk out; "
            f"K {f(c['K']['mean'], 3)} ({f(c['K']['min'], 3)}..{f(c['K']['max'], 3)}), "
            f"rotation {f(c['rotation_deg']['mean'], 1)} deg "
            f"({f(c['rotation_deg']['min'], 1)}..{f(c['rotation_deg']['max'], 1)}), "
            f"heading variant "
            + ", ".join(f"{v} in {n} folds" for v, n in c.get("heading_variant", {}).items())
            + ", matcher "
            + ", ".join(f"{v} in {n} folds" for v, n in c.get("matcher_variant", {}).items())
            + ", adaptive "
            + ", ".join(f"{v} in {n} folds" for v, n in c.get("adaptive_variant", {}).items())
            + ", "
            f"map {f(c['n_rp']['mean'], 0)} RPs / {f(c['n_ap']['mean'], 0)} APs"
        )
        for key, title in (
            ("summary", "every scheme from its first fix"),
            ("summary_true_start", "TRUTH-INITIALISED start"),
        ):
            if key not in g:
                continue
            s = g[key]
            lines.append(f"  [{title}]  errors in m at the ground-truth times")
            lines.append(
                f"  {'scheme':<10}{'n':>6}{'mean':>8}{'median':>8}{'p75':>8}{'p90':>8}"
                f"{'max':>8}{'rmse':>8}{'ipin':>8}{'floor%':>8}{'>15m':>10}"
            )
            for name, r in s["schemes"].items():
                share = r["share_walks_mean_over_15m"]
                lines.append(
                    f"  {name:<10}{r['n']:>6}{f(r['mean']):>8}{f(r['median']):>8}"
                    f"{f(r['p75']):>8}{f(r['p90']):>8}{f(r['max']):>8}{f(r['rmse']):>8}"
                    f"{f(r['ipin_score']):>8}{f(100 * r['floor_hit_rate'], 1):>8}"
                    f"{(f(100 * share, 1) + '%') if share == share else '-':>10}"
                )
            lines.append(
                f"  adaptive vs wifi_only: mean error reduced by "
                f"{f(s['adaptive_vs_wifi_only_reduction_pct'], 1)} %  (>15m = share of walks "
                f"whose mean error exceeds {ROBUST_MEAN_M:g} m; ipin = p75 of 2-D error + "
                f"{IPIN_FLOOR_PENALTY_M:g} m x |floor error|)"
            )
        for e in g["failed"] + g["fold_errors"]:
            lines.append(f"  failed {e['walk']}: {e['error']}")
    return "\n".join(lines)


# --- CLI -------------------------------------------------------------------------------------------


def add_fusion_parser(sub) -> None:
    """Declare ``stridefix realbench [fusion]``."""
    import argparse

    d = sub.add_parser(
        "fusion",
        help="all fusion schemes on real walks, leave one walk out (default benchmark)",
        description="Leave one walk out per floor (msindoor) or building (gsd): build the site "
        "(walk-mode radio map, floors, map rotation) and Weinberg K from the other "
        "walks, replay the held-out walk through stridefixd --site and score all six "
        "schemes at its ground-truth times. Writes results.json, an HTML report next "
        "to it, and per-walk work files under its folder.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    d.add_argument(
        "dirs",
        nargs="+",
        metavar="DIR",
        help="msindoor: floor folders (site1/F2 or its path_data_files); gsd: folders "
        "of GetSensorData logs (or log files)",
    )
    d.add_argument("--format", required=True, choices=FORMATS, help="data set format")
    d.add_argument("--out", required=True, metavar="results.json", help="JSON results file")
    d.add_argument(
        "--stridefixd",
        default=os.environ.get("STRIDEFIXD", str(rb.DEFAULT_STRIDEFIXD)),
        metavar="PATH",
        help="firmware binary ($STRIDEFIXD or build/firmware/stridefixd)",
    )
    d.add_argument(
        "--limit",
        type=int,
        default=None,
        metavar="N",
        help="only the first N walks of each group (sorted by name)",
    )
    d.add_argument("--jobs", "-j", type=int, default=2, metavar="N", help="parallel workers")
    d.add_argument(
        "--true-start", action="store_true", help="also run every walk truth-initialised (labelled as such)"
    )
    d.add_argument("--cell-size-m", type=float, default=DEFAULT_CELL_SIZE_M, help="radio-map grid cell [m]")
    d.add_argument(
        "--min-count",
        type=int,
        default=DEFAULT_MIN_COUNT,
        help="radio map: drop (cell, AP) entries heard in fewer scans",
    )
    d.add_argument(
        "--max-wifi-age-s",
        type=float,
        default=None,
        help="importer: drop cached Wi-Fi entries older than this [s] (default: the importer's)",
    )
    d.add_argument(
        "--set",
        dest="param_sets",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="firmware parameter for every replay (stridefixd --set; repeatable): what-if "
        "runs; recorded in results.json",
    )
    d.add_argument(
        "--cache", default=None, metavar="DIR", help="import cache (default: <folder of results.json>/cache)"
    )
    d.add_argument("--reimport", action="store_true", help="ignore the cached imports")
    d.add_argument("--no-report", action="store_true", help="skip the HTML report")
    d.add_argument("--quiet", "-q", action="store_true", help="no progress lines on stderr")
    d.set_defaults(_bench=_run_fusion_cli)


def _run_fusion_cli(args) -> int:
    try:
        doc = run_fusion(
            args.format,
            args.dirs,
            args.out,
            args.stridefixd,
            args.limit,
            args.jobs,
            args.reimport,
            args.true_start,
            args.max_wifi_age_s,
            args.cell_size_m,
            args.min_count,
            args.cache,
            not args.no_report,
            args.quiet,
            args.param_sets,
        )
    except rb.RealbenchError as exc:
        print(f"stridefix realbench: error: {exc}", file=sys.stderr)
        return 2
    print(format_tables(doc))
    extra = f" and {doc['report']}" if doc.get("report") else ""
    print(
        f"wrote {args.out}{extra} ({doc['run_s']['total']:.1f} s: prepare "
        f"{doc['run_s']['prepare']:.1f} s, folds {doc['run_s']['folds']:.1f} s)"
    )
    scored = sum(g["summary"]["schemes"].get("kalman", {}).get("n", 0) for g in doc["groups"])
    return 0 if scored else 1
