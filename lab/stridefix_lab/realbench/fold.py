"""Phase 3 of ``realbench fusion``, one fold: the held-out walk replayed on a site learned from the
other walks of its group, every scheme scored at the walk's ground-truth times.

The fold's site is the walk-mode radio map of ``total − held`` (sufficient statistics, so no map is
rebuilt from scratch) with the fold's map rotation and floors, and the building content its training
walks give (walls, geo-reference, beacons: :mod:`.sitecontent`); the replay adds
``--set stride.weinberg_k=K`` and the tuning axes' chosen settings (:mod:`.tuning`). One replay per
start mode: the firmware decides the starting floor itself (a vote of the fixes held against the
barometer, firmware/core/sf_floor_vote.h). Everything a worker needs comes in its :class:`FoldJob`: no
state outside it.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import LogReadError
from stridefix_analyzer.radiomap.build import WalkStats

from stridefix_lab.realbench import lsd
from stridefix_lab.realbench.reference import run_references
from stridefix_lab.realbench.reference_sensors import Track
from stridefix_lab.realbench.sitecontent import GroupContent, apply_fields, train_placed

#: 1: with the matcher's map levels averaged over all of a cell's scans (misses at fill), one detection
#: is already weak evidence, not noise to drop; 2 cost 2.4 m of Wi-Fi-only mean error on msindoor
DEFAULT_MIN_COUNT = 1
STATS_KEYS = ("n", "mean", "median", "p75", "p90", "p95", "max", "rmse")


@dataclasses.dataclass(frozen=True)
class FoldJob:
    """One fold: the held-out walk, what was learned without it, and the statistics to subtract."""

    index: int  # the walk's index among all prepared walks
    walk: str
    group: str
    dir: Path
    import_log: str
    firmware: Firmware
    K: float
    rotation_deg: float
    rotation_learned: bool
    floor_heights_m: Sequence[float]
    floor_heights_source: str
    lowest_floor: int
    min_count: int
    true_start: bool
    #: the user's --set, then every axis's chosen settings
    param_sets: Sequence[str]
    #: axis name -> chosen candidate; then further per-fold records of the choosers
    variants: Mapping[str, str]
    extra: Mapping[str, Any]
    first_waypoint: tuple[int, float, float, int]
    total: WalkStats
    held: WalkStats
    #: site_t fields measured for this fold (the ekf's fix-error model), written into its site
    site_fields: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    #: the group's building content (walls, geo, beacons) and this walk's index in its group
    content: GroupContent | None = None
    content_index: int = -1
    #: the textbook references' inputs (:mod:`.reference`): the held-out walk's and the training walks'
    reference_held: Track | None = None
    reference_training: tuple[Track, ...] = ()


def fold_site(
    total: WalkStats,
    held: WalkStats,
    *,
    name: str,
    rotation_deg: float,
    floor_heights_m: Sequence[float],
    lowest_floor: int,
    min_count: int = DEFAULT_MIN_COUNT,
) -> tuple[Any, dict[str, Any]]:
    """The fold's site: radio map of ``total − held`` (sufficient statistics) with the given
    rotation and floors; returns (site, summary)."""
    stats = total - held
    return stats.to_site(
        min_count=min_count,
        name=name,
        map_rotation_deg=rotation_deg,
        floor_heights_m=floor_heights_m,
        lowest_floor=lowest_floor,
        source=f"stridefix-lab realbench: leave-one-walk-out fold without {name}",
    )


def run_fold(job: FoldJob) -> dict[str, Any]:
    """Phase 3 of one walk: write its fold's site, replay it with ``--site``, score every scheme."""
    from stridefix_analyzer.io.sitefile import write_site
    from stridefix_analyzer.radiomap.build import RadioMapInputError
    from stridefix_analyzer.scoring.analyze import run_analyze
    from stridefix_analyzer.scoring.floor_height import from_table
    from stridefix_analyzer.scoring.metrics import MetricsInputError

    t0 = time.perf_counter()
    out: dict[str, Any] = {"walk": job.walk, "group": job.group, "error": None, "fold": {}}
    job.dir.mkdir(parents=True, exist_ok=True)
    try:
        site, summ = fold_site(
            job.total,
            job.held,
            name=job.walk,
            rotation_deg=job.rotation_deg,
            floor_heights_m=job.floor_heights_m,
            lowest_floor=job.lowest_floor,
            min_count=job.min_count,
        )
    except RadioMapInputError as exc:
        out["error"] = f"no site for this fold: {exc}"
        return out
    site_fields = dict(job.site_fields)
    lsd_scheme = site_fields.pop(lsd.SITE_KEY, None)
    for name, value in site_fields.items():
        setattr(site, name, value)
    content: dict[str, Any] = {}
    if job.content is not None:
        fields, content = job.content.fold_fields(job.content_index)
        dropped = apply_fields(site, fields)
        content.update({f"{k}s_off_site_floors": v for k, v in dropped.items() if v})
    if lsd_scheme is not None:
        # one building, one context per floor, the scheme chosen on the training walks (.lsd)
        from stridefix_analyzer.radiomap.contexts import single_building_context_map

        placed = train_placed(job.content, job.content_index) if job.content is not None else None
        site = single_building_context_map(site, scheme=lsd_scheme, ble_placed=placed) or site
        content["controller_scheme"] = lsd_scheme
    site_path = job.dir / "site.sfsite"
    write_site(site_path, site)
    out["fold"] = {
        "K": job.K,
        "rotation_deg": job.rotation_deg,
        **{f"{axis}_variant": v for axis, v in job.variants.items()},
        **job.extra,
        "n_rp": site.n_rp,
        "n_ap": site.n_ap,
        "n_entries": site.n_entries,
        "n_floors": site.n_floors,
        "lowest_floor": site.lowest_floor,
        "floor_heights_m": [float(h) for h in site.floor_height_m],
        "floor_heights_source": job.floor_heights_source,
        "scans_used": summ["scans"].get("used"),
        "n_walls": site.n_walls,
        "n_beacons": site.n_beacons,
        "has_geo": bool(site.has_geo),
        **{f"content_{k}": v for k, v in content.items()},
    }
    sets = list(job.param_sets)
    if math.isfinite(job.K):
        sets.append(f"stride.weinberg_k={job.K:.6f}")
    runs: list[tuple[str, list[str]]] = [("fixes", [])]
    if job.true_start:
        _, x, y, f = job.first_waypoint
        runs.append(
            (
                "true_start",
                ["init.use_config_pose=1", f"init.x_m={x:.3f}", f"init.y_m={y:.3f}", f"init.floor={f}"],
            )
        )
    for tag, extra in runs:
        fw_log = job.dir / ("stridefixd.lcmlog" if tag == "fixes" else f"stridefixd_{tag}.lcmlog")
        replay: dict[str, Any] = {
            "input": f"lcmlog:{job.import_log}",
            "site": site_path,
            "log": fw_log,
            "check": False,
        }
        proc = job.firmware.run(**replay, sets=sets + extra)
        if proc.returncode != 0:
            out["error"] = f"stridefixd exit {proc.returncode}: {proc.stderr.strip()[-300:]}"
            return out
        adir = job.dir if tag == "fixes" else job.dir / tag
        label = f"{job.walk}: leave-one-walk-out, " + (
            "every scheme from its first fix" if tag == "fixes" else "truth-initialised"
        )
        logs = [str(fw_log), job.import_log]
        heights = from_table(
            site.floor_height_m, site.lowest_floor, f"the fold's site ({job.floor_heights_source})"
        )
        try:
            try:
                analysis, metrics = run_analyze(
                    logs, str(adir), label=label, truth_source="waypoint", heights=heights
                )
            except MetricsInputError as exc:
                if "source" not in str(exc):
                    raise
                analysis, metrics = run_analyze(logs, str(adir), label=label, heights=heights)
        except (LogReadError, MetricsInputError) as exc:
            out["error"] = f"cannot score: {exc}"
            return out
        out[tag] = score_walk(metrics)
        out.setdefault("fix_sources", {})[tag] = analysis["fix_sources"]
    if job.reference_held is not None:
        poses, info = run_references(
            job.reference_held, job.reference_training, site.floor_height_m, job.true_start
        )
        truth = job.reference_held.truth
        out["references"] = {
            tag: {n: score_poses(p, truth, heights) for n, p in d.items()} for tag, d in poses.items()
        }
        out["fold"]["reference"] = info
    out["run_s"] = time.perf_counter() - t0
    return out


def score_poses(pose: Any, truth: Any, heights: Any) -> dict[str, Any]:
    """One walk of a Python-computed track (a :mod:`.reference`): the same keys and functions as a
    scheme's row of :func:`score_walk` (the causal match at the truth times, :mod:`..scoring.metrics`)."""
    import numpy as np
    from stridefix_analyzer.io.logread import Table
    from stridefix_analyzer.scoring import iso18305
    from stridefix_analyzer.scoring.metrics import error_stats, ipin_score, match_causal, scored_errors

    cols = {c: truth[c] for c in ("t_us", "x_m", "y_m", "floor")}
    m = match_causal(pose, Table({**cols, "heading_rad": np.full(len(truth), np.nan)}))
    err, ferr = scored_errors(m)
    stats = error_stats(err)
    return {
        **{k: stats[k] for k in STATS_KEYS},
        "unscored": int(np.count_nonzero(~m["scored"])),
        "floor_hit_rate": float(np.mean(ferr == 0)) if len(ferr) else math.nan,
        "ipin_score": ipin_score(err, ferr),
        "iso18305": iso18305.terms(m, heights),
        "errors_m": err.tolist(),
        "floor_errors": ferr.tolist(),
    }


def score_walk(metrics: Any) -> dict[str, dict[str, Any]]:
    """Per scheme of one walk: stats, floor hit rate, IPIN score, ISO/IEC 18305 terms and the raw
    per-sample errors."""
    from stridefix_analyzer.scoring.metrics import scored_errors

    res = {}
    for s in metrics.schemes.values():
        err, ferr = scored_errors(s.match)
        res[s.name] = {
            **{k: s.summary["position_error_m"][k] for k in STATS_KEYS},
            "unscored": s.summary["unscored"],
            "floor_hit_rate": s.summary["floor_hit_rate"],
            "ipin_score": s.summary["ipin_score"],
            "iso18305": s.summary["iso18305"],
            "errors_m": err.tolist(),
            "floor_errors": ferr.tolist(),
        }
    return res
