"""``stridefix-lab realbench --format NAME DIR... --out results.json``: the fusion schemes on real walks,
leave one walk out.

Groups come from the data set (:meth:`~stridefix_analyzer.datasets.protocol.Dataset.find_walks`, then
``regroup`` once the walks are read: msindoor per floor folder, gsd per folder and building). Within a
group every walk is scored once, with everything the estimator may know taken from the *other* walks
of the group only (DESIGN.md, evaluation protocol):

1. every walk is imported (cached under ``OUT/cache/<group>``) and replayed without a site
   (:mod:`.prepare`): its sufficient statistics;
2. per group the tuning rows choose per fold (:mod:`.tuning`), and per fold the constants follow: the
   stride constant K (:func:`stridefix_analyzer.radiomap.strides.calibrate_lowo`), the map rotation of the chosen heading
   candidate (:func:`stridefix_analyzer.radiomap.heading.learn_rotation_deg`) and the floors (:mod:`.floors`);
3. walk i is replayed on its fold's site (with the walls, geo-reference and beacons of the
   training walks, :mod:`.sitecontent`) with every scheme and scored at its ground-truth times
   (:mod:`.fold`). ``--true-start`` adds a run labelled truth-initialised. Beside the schemes, two
   textbook references computed in Python from the same walks, training walks, starts and truth
   (:mod:`.reference`: ``reference_pdr``, ``reference_ekf``); a scheme that scores worse than its
   reference is listed in ``loses_to_reference``.

Outputs (:mod:`.summary`): ``results.json``, the HTML report next to it (:mod:`.report`), and the
per-walk work files under ``OUT/realbench_work/<group>/<walk>`` (site file, stridefixd log,
metrics.json, analysis.npz).

Phases 1 and 3 and the inner cross-validation of phase 2 are independent tasks (a walk, a fold, a
replay) on ``--scheduler`` (:mod:`stridefix_analyzer.parallel`: serial, local processes, a Dask
LocalCluster or a Dask scheduler's workers), one runner for the whole run; their results are merged in
task order, so every scheduler gives the same results.json (apart from ``run_s`` and ``params.jobs``/
``params.scheduler``).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import sys
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from stridefix_analyzer.console import Progress
from stridefix_analyzer.datasets.protocol import Dataset, WalkGroup
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.results import write_realbench_results
from stridefix_analyzer.parallel import TaskRunner, WorkerFiles, is_remote, task_runner
from stridefix_analyzer.radiomap.build import WalkStats
from stridefix_analyzer.radiomap.heading import (
    ROT_MIN_RESULTANT,
    ROT_MIN_SEGMENT_M,
    ROT_MIN_STEPS,
    learn_rotation_deg,
)
from stridefix_analyzer.radiomap.strides import build_segments, calibrate_lowo, stride_k
from stridefix_analyzer.scoring.metrics import IPIN_FLOOR_PENALTY_M

from stridefix_lab.realbench import priors, tuning
from stridefix_lab.realbench.floors import DEFAULT_STOREY_M, fold_floors
from stridefix_lab.realbench.fold import DEFAULT_MIN_COUNT, FoldJob, run_fold
from stridefix_lab.realbench.prepare import PrepareJob, prepare
from stridefix_lab.realbench.select_sites import SelectionSites
from stridefix_lab.realbench.sitecontent import ContentOptions, group_content
from stridefix_lab.realbench.summary import ROBUST_MEAN_M, build_doc, strip_samples
from stridefix_lab.realbench.walks import check_some_imported, dataset, find_groups, firmware

DEFAULT_CELL_SIZE_M = 2.0


@dataclasses.dataclass(frozen=True)
class FusionConfig:
    """One run of the benchmark (the ``stridefix-lab realbench fusion`` options)."""

    fmt: str
    dirs: Sequence[str | Path]
    out_json: Path
    stridefixd: str | Path | None = None  # None: $STRIDEFIXD or the CMake build's
    limit: int | None = None
    jobs: int = 2  # worker processes of the scheduler "processes" or "local"
    #: where the tasks run (:func:`stridefix_analyzer.parallel.check_scheduler`)
    scheduler: str | None = "processes"
    reimport: bool = False
    true_start: bool = False
    max_wifi_age_s: float | None = None  # None: the data set's default
    cell_size_m: float = DEFAULT_CELL_SIZE_M
    min_count: int = DEFAULT_MIN_COUNT
    cache_dir: str | Path | None = None
    report: bool = True
    quiet: bool = False
    param_sets: Sequence[str] = ()
    #: the building content the fold sites carry (walls, beacons, geo-reference)
    content: ContentOptions = ContentOptions()


@dataclasses.dataclass(frozen=True)
class Part:
    """A group after the walks were read: its walks (indices into all walks) and its folders."""

    label: str
    walk_ids: list[int]
    floor_dir: Path | None
    work: Path
    folder: Path | None = None


@dataclasses.dataclass(frozen=True)
class Run:
    """What every phase of one run shares."""

    cfg: FusionConfig
    dataset: Dataset
    firmware: Firmware
    axes: tuple[tuning.Axis, ...]
    max_wifi_age_s: float
    out_dir: Path
    stream: TextIO
    tasks: TaskRunner  # where the walks, replays and folds run


def run_fusion(cfg: FusionConfig) -> dict[str, Any]:
    """Run the leave-one-walk-out fusion benchmark; write ``cfg.out_json`` (+ the HTML report).

    Returns the JSON document (non-finite numbers still NaN). Raises :class:`.walks.RealbenchError`.
    """
    t_start = time.perf_counter()
    with start_run(cfg) as (run, groups):
        return _run_fusion(run, groups, t_start)


def _run_fusion(run: Run, groups: list[WalkGroup], t_start: float) -> dict[str, Any]:
    cfg, fw, stream = run.cfg, run.firmware, run.stream
    walks, parts = prepare_walks(run, groups)  # phase 1
    t_prep = time.perf_counter() - t_start
    planned = [plan_group(run, p, walks) for p in parts]  # phase 2
    group_info = {p.label: info for p, (info, _) in zip(parts, planned)}
    fold_jobs = [j for _, jobs in planned for j in jobs]
    t3 = time.perf_counter()
    results = run_folds(run, fold_jobs)  # phase 3
    job_of = {j.walk: j for j in fold_jobs}
    labels = [p.label for p in parts]
    doc = build_doc(cfg.fmt, cfg.dirs, labels, group_info, walks, results, job_of, run.axes, cfg.true_start)
    doc["params"] = _params(run)
    doc["stridefixd"] = {"path": str(fw.path), "version": fw.version()}
    doc["run_s"] = {
        "prepare": t_prep,
        "folds": time.perf_counter() - t3,
        "total": time.perf_counter() - t_start,
    }
    if cfg.report:
        from stridefix_lab.realbench.report import write_report

        html = cfg.out_json.with_suffix(".html")
        write_report(doc, html)
        doc["report"] = str(html)
    doc["run_s"]["total"] = time.perf_counter() - t_start
    write_realbench_results(cfg.out_json, strip_samples(doc))
    if cfg.quiet:
        stream.close()
    return doc


@contextlib.contextmanager
def start_run(cfg: FusionConfig) -> Iterator[tuple[Run, list[WalkGroup]]]:
    """The data set, the checked firmware, the tuning axes, the output folder, the progress stream
    and the task runner of a run (closed after), and its walk groups (shared with ``realbench
    crowd-map``). Raises RealbenchError, or SchedulerError when the scheduler or its workers cannot run it."""
    if is_remote(cfg.scheduler):
        # a remote worker's working folder is not ours: every path the tasks see is absolute
        cfg = dataclasses.replace(
            cfg,
            dirs=[Path(d).resolve() for d in cfg.dirs],
            out_json=cfg.out_json.resolve(),
            stridefixd=Path(cfg.stridefixd or Firmware().path).resolve(),
            cache_dir=Path(cfg.cache_dir).resolve() if cfg.cache_dir else None,
        )
    ds = dataset(cfg.fmt)
    # the data set's own overrides first, the user's --set after them (the later one wins)
    cfg = dataclasses.replace(cfg, param_sets=(*ds.firmware_sets, *cfg.param_sets))
    fw = firmware(cfg.stridefixd or Firmware().path, cfg.param_sets)
    age = ds.defaults.max_wifi_age_s if cfg.max_wifi_age_s is None else cfg.max_wifi_age_s
    out_dir = cfg.out_json.parent if str(cfg.out_json.parent) else Path(".")
    out_dir.mkdir(parents=True, exist_ok=True)
    groups = find_groups(ds, cfg.dirs, cfg.limit)
    stream = open(os.devnull, "w") if cfg.quiet else sys.stderr
    rows = tuning.axes(cfg.param_sets)
    if not cfg.content.controller:
        rows = tuple(a for a in rows if a.name != "lsd")
    cache = Path(cfg.cache_dir) if cfg.cache_dir else out_dir / "cache"
    cache.mkdir(parents=True, exist_ok=True)
    # what the tasks read and write by path: a Dask worker must see the same (checked before the first)
    files = WorkerFiles(read=[*cfg.dirs], write=[out_dir, cache], same=[fw.path])
    with task_runner(cfg.scheduler, cfg.jobs, files) as runner:
        yield Run(cfg, ds, fw, rows, age, out_dir, stream, runner), groups


def prepare_walks(run: Run, groups: list[WalkGroup]) -> tuple[list[dict[str, Any]], list[Part]]:
    """Phase 1 of every walk, in parallel; then the data set's regrouping of each group."""
    cfg, heading = run.cfg, next(a for a in run.axes if a.name == "heading").candidates
    jobs, owner = [], []
    for g in groups:
        safe = g.label.replace("/", "-")
        cache = Path(cfg.cache_dir) / safe if cfg.cache_dir else run.out_dir / "cache" / safe
        work = run.out_dir / "realbench_work" / safe
        options = {"max_wifi_age_s": run.max_wifi_age_s, **g.options}
        for tr in g.walks:
            owner.append((g, work))
            jobs.append(
                PrepareJob(
                    trace=tr,
                    dataset=run.dataset,
                    work_dir=work,
                    cache_dir=cache,
                    firmware=run.firmware,
                    read_options=options,
                    reimport=cfg.reimport,
                    cell_size_m=cfg.cell_size_m,
                    param_sets=list(cfg.param_sets),
                    heading_candidates=heading,
                )
            )
    prog = Progress(f"prepare ({run.tasks.describe()})", len(jobs), run.stream)

    def done(_: int, w: dict[str, Any]) -> None:
        steps = w["error"] or f"{len(w['step_t_us'])} steps, {len(w['waypoint_t_us'])} waypoints"
        prog.step(f"{w['walk']}: {steps}")

    walks: list[dict[str, Any]] = run.tasks.map(prepare, jobs, on_result=done)
    check_some_imported(walks)
    parts = []
    for g in groups:
        ids = [i for i, (o, _) in enumerate(owner) if o is g]
        work = owner[ids[0]][1] if ids else run.out_dir / "realbench_work" / g.label.replace("/", "-")
        for label, mine in run.dataset.regroup(g, [walks[i].get("import") for i in ids]):
            parts.append(Part(label, [ids[k] for k in mine], g.floor_dir, work, g.folder))
    return walks, parts


def plan_group(run: Run, part: Part, walks: list[dict[str, Any]]) -> tuple[dict[str, Any], list[FoldJob]]:
    """Phase 2 of one group: the tuning rows' choices and every fold's constants."""
    ok = [i for i in part.walk_ids if not walks[i]["error"]]
    failed = [
        {"walk": walks[i]["walk"], "error": walks[i]["error"]} for i in part.walk_ids if walks[i]["error"]
    ]
    info: dict[str, Any] = {
        "label": part.label,
        "walks": len(part.walk_ids),
        "ran": len(ok),
        "failed": failed,
    }
    info["floor_dir"] = str(part.floor_dir) if part.floor_dir else None
    if not ok:
        return info, []
    sub = [walks[i] for i in ok]
    seg = build_segments(sub)
    used = seg["excluded"] == ""
    ks = calibrate_lowo(seg["walk"][used], seg["true_m"][used], seg["weinberg"][used], np.arange(len(sub)))
    total = WalkStats.total([w["stats"] for w in sub])
    rotation = [w["rotation"] for w in sub]
    info["K_all_walks"] = stride_k(seg, used)
    heading = next(a for a in run.axes if a.name == "heading").candidates
    content = group_content(run.dataset, part.folder, part.floor_dir, sub, run.cfg.content)
    sites = SelectionSites(total, sub, seg, used, rotation, heading, run.cfg.min_count, content)
    group = tuning.Group(
        sub, rotation, sites, run.firmware, part.work / "select", run.cfg.param_sets, run.tasks, run.stream
    )
    choices = tuning.choose(run.axes, group)
    for c in choices.values():
        info.update(c.info)
    info["site_content"] = {
        "options": dataclasses.asdict(run.cfg.content),
        **content.report,
    }
    jobs = []
    for j, i in enumerate(ok):
        variants = {name: c.per_walk[j] for name, c in choices.items()}
        # the map rotation comes from the STEP headings of the chosen heading candidate
        rot = learn_rotation_deg([r[variants["heading"]] for r in rotation], exclude=j)
        heights, src, lowest = fold_floors([w for jj, w in enumerate(sub) if jj != j], sub[j]["floors"])
        # the ekf's start priors: this walk's likely offset from the fold's rotation and K
        given = {kv.split("=", 1)[0].strip() for kv in run.cfg.param_sets}
        ekf_priors = {
            k: v
            for k, v in priors.ekf_start_priors(
                [r[variants["heading"]] for r in rotation],
                seg["walk"][used],
                seg["true_m"][used],
                seg["weinberg"][used],
                j,
            ).items()
            if k not in given
        }
        jobs.append(
            FoldJob(
                index=i,
                walk=walks[i]["walk"],
                group=part.label,
                dir=part.work / walks[i]["walk"],
                import_log=walks[i]["import_log"],
                firmware=run.firmware,
                K=float(ks[j]),
                rotation_deg=0.0 if not math.isfinite(rot) else rot,
                rotation_learned=math.isfinite(rot),
                floor_heights_m=heights,
                floor_heights_source=src,
                lowest_floor=lowest,
                min_count=run.cfg.min_count,
                true_start=run.cfg.true_start,
                param_sets=[
                    *run.cfg.param_sets,
                    *tuning.settings(run.axes, variants),
                    *(f"{k}={v:.6g}" for k, v in ekf_priors.items()),
                ],
                variants=variants,
                extra={
                    **{k: v for c in choices.values() for k, v in c.extra[j].items()},
                    "ekf_priors": ekf_priors,
                },
                first_waypoint=walks[i]["first_waypoint"],
                total=total,
                held=walks[i]["stats"],
                site_fields=tuning.walk_site_fields(choices, j),
                content=content,
                content_index=j,
                reference_held=sub[j].get("reference"),
                reference_training=tuple(
                    w["reference"] for jj, w in enumerate(sub) if jj != j and w.get("reference") is not None
                ),
            )
        )
    return info, jobs


def run_folds(run: Run, jobs: list[FoldJob]) -> list[dict[str, Any]]:
    """Phase 3: every fold, on the run's scheduler; results in the order of ``jobs``."""
    prog = Progress("fold", len(jobs), run.stream)

    def done(_: int, r: dict[str, Any]) -> None:
        k = r.get("fixes", {}).get("kalman", {}).get("mean")
        note = r["error"] or (f"kalman mean {k:.1f} m" if k is not None else "scored")
        prog.step(f"{r['walk']}: {note}")

    return run.tasks.map(run_fold, jobs, on_result=done)


def _params(run: Run) -> dict[str, Any]:
    cfg = run.cfg
    return {
        "cell_size_m": cfg.cell_size_m,
        "min_count": cfg.min_count,
        "firmware_sets": list(cfg.param_sets),
        "max_wifi_age_s": run.max_wifi_age_s,
        "limit": cfg.limit,
        "jobs": cfg.jobs,
        "scheduler": run.tasks.describe(),
        "robust_mean_m": ROBUST_MEAN_M,
        "ipin_floor_penalty_m": IPIN_FLOOR_PENALTY_M,
        "rotation": {
            "min_segment_m": ROT_MIN_SEGMENT_M,
            "min_resultant": ROT_MIN_RESULTANT,
            "min_steps": ROT_MIN_STEPS,
        },
        "default_storey_m": DEFAULT_STOREY_M,
        "site_content": dataclasses.asdict(cfg.content),
    }
