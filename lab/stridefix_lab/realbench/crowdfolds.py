"""The crowd positions of ``realbench crowd-map``'s folds: what each fold's crowd knows, learned from
its training walks' anchors only.

A crowd map has no truth, but every walk carries anchors (every K-th waypoint here), and the fleet of
training walks together says more than one walk alone (the fleet priors of
:mod:`..crowd.graph`). Per fold (test walk left out), from the training walks' anchors:

* **the heading variant** (:data:`stridefix_analyzer.radiomap.heading.HEADING_VARIANTS`: learned or fixed mounting offset, mag
  gate) whose STEP headings the walks agree on best: the smallest robust spread of the per-walk heading
  bias that maps each walk's dead reckoning onto its anchors (:func:`~..crowd.graph.walk_similarity`).
  A heading the phone keeps consistent from walk to walk is one the map's rotation can correct;
  ``realbench fusion`` chooses the same axis by the truth directions of every waypoint;
* **the fleet priors** (stride scale, heading bias, their spreads; :func:`~..crowd.graph.priors_from`)
  of that variant: a walk with one or two anchors gets its rotation and scale from the others.

Each training walk is then graph-solved alone (no Wi-Fi rows: one walk's solve never reads another
walk's scans) with its own anchors, its STEP stream and those priors; scans whose solved position has a
posterior σ above ``max_sigma_m`` stay out of the map. Folds that learned the same (variant, priors)
share one solve per walk: a median over 101 of 102 walks takes few distinct values.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from typing import Any, TextIO

from stridefix_analyzer.console import Progress
from stridefix_analyzer.crowd.graph import FleetPriors, agreed_variant
from stridefix_analyzer.parallel import TaskRunner
from stridefix_analyzer.radiomap.build import WalkStats

#: a (heading variant, fleet priors) pair: what one fold's crowd learned
Choice = tuple[str, FleetPriors]


@dataclasses.dataclass(frozen=True)
class CrowdJob:
    """One walk's crowd work (sent to a worker): its site-less replay logs per heading variant and its
    imported log; for a solve, the variant and priors to use."""

    walk: str
    fw_logs: tuple[tuple[str, str], ...]  # (heading variant, its replay log with the STEP stream)
    import_log: str
    anchors: str
    solver: str
    cell_size_m: float
    max_sigma_m: float
    variant: str = ""
    priors: FleetPriors | None = None


def walk_similarities(job: CrowdJob) -> dict[str, Any]:
    """Per heading variant, the walk's (scale, heading bias) on its own anchors, or None (too few
    anchors); ``error`` says why a walk has none at all."""
    from stridefix_analyzer.crowd.graph_run import anchor_similarities
    from stridefix_analyzer.crowd.walks import CrowdInputError, load_walks
    from stridefix_analyzer.io.logread import LogReadError

    out: dict[str, Any] = {"walk": job.walk, "error": None, "sims": {}}
    for variant, fw_log in job.fw_logs:
        try:
            walks = load_walks([(fw_log, job.import_log)])
        except (CrowdInputError, LogReadError) as exc:
            out["error"] = f"crowd walk unreadable: {exc}"
            return out
        out["sims"][variant] = anchor_similarities(walks, job.anchors)[0]
    return out


def crowd_walk(job: CrowdJob) -> dict[str, Any]:
    """Solve one walk on the graph (``job.variant``'s STEP stream, ``job.priors``) and return the
    walk-mode map statistics of its scans at the solved positions (``stats``; scans with σ above
    ``max_sigma_m`` left out and counted), the rows used and the position errors; ``error`` says why
    not."""
    from stridefix_analyzer.crowd.graph_run import solve_walks_graph
    from stridefix_analyzer.crowd.graph_solve import position_sigma_m
    from stridefix_analyzer.crowd.sites import drop_uncertain_scans, graph_errors, scan_sigma_m, solved_truth
    from stridefix_analyzer.crowd.walks import CrowdInputError, load_walks
    from stridefix_analyzer.io.logread import LogReadError
    from stridefix_analyzer.radiomap.build import RadioMapInputError, Recording, load_recordings

    t0 = time.perf_counter()
    out: dict[str, Any] = {"walk": job.walk, "error": None, "variant": job.variant}
    try:
        walks = load_walks([(dict(job.fw_logs)[job.variant], job.import_log)])
        # band "all": every scan with an AP is a point of the graph, so each scan of the map gets
        # its own solved position (without Wi-Fi rows the band changes nothing else)
        run = solve_walks_graph(walks, anchors=job.anchors, band="all", solver=job.solver, priors=job.priors)
        recs = load_recordings([job.import_log])
    except (CrowdInputError, LogReadError, RadioMapInputError) as exc:
        out["error"] = f"crowd solve failed: {exc}"
        return out
    truth = solved_truth(walks[0], 0, run.xy_m, run.points)
    sigma_m = position_sigma_m(run.problem, run.solution)
    crowd, dropped = [], 0
    for r in recs:
        kept, n = drop_uncertain_scans(r, scan_sigma_m(run, sigma_m, 0, r.wifi["t_us"]), job.max_sigma_m)
        crowd.append(Recording(kept.files, kept.wifi, kept.wifi_ap, truth, kept.ble))
        dropped += n
    out["dropped_uncertain"] = dropped
    out["stats"] = WalkStats.from_recordings(crowd, cell_size_m=job.cell_size_m)
    out["rows"] = run.info["rows"]
    out["solver"] = run.info["solver"].get("solver")
    out["positions"] = graph_errors(run)
    out["run_s"] = time.perf_counter() - t0
    return out


def choose(sims: Sequence[Mapping[str, Any]], variants: Sequence[str]) -> Choice:
    """:func:`~..crowd.graph.agreed_variant` of one fold's training walks (their per-walk
    similarities ``sims``, :func:`walk_similarities`): the module docstring's choice."""
    return agreed_variant({v: [s["sims"][v] for s in sims if s["sims"].get(v) is not None] for v in variants})


def solve_folds(
    jobs: Mapping[int, CrowdJob],
    folds: Mapping[int, Sequence[int]],
    variants: Sequence[str],
    tasks: TaskRunner,
    stream: TextIO,
) -> tuple[dict[int, Choice], dict[Choice, dict[int, dict[str, Any]]]]:
    """``jobs``: walk index → its job; ``folds``: test walk index → its training walk indices.
    Returns each fold's choice and, per distinct choice, every walk's :func:`crowd_walk` result
    (walks of a fold's training set that failed: ``error`` set); every task on ``tasks``."""
    prog = Progress("crowd anchors", len(jobs), stream)

    def told(_: int, s: dict[str, Any]) -> None:
        n = sum(v is not None for v in s["sims"].values())
        prog.step(f"{s['walk']}: {s['error'] or f'{n} of {len(variants)} variants tell'}")

    ids = list(jobs)
    sims = dict(zip(ids, tasks.map(walk_similarities, [jobs[i] for i in ids], on_result=told)))
    choice = {
        t: choose([sims[i] for i in train if not sims[i]["error"]], variants) for t, train in folds.items()
    }
    distinct = list(dict.fromkeys(choice.values()))
    ok = [i for i in jobs if not sims[i]["error"]]
    solved: dict[Choice, dict[int, dict[str, Any]]] = {c: {} for c in distinct}
    for i in jobs:
        if sims[i]["error"]:
            for c in distinct:
                solved[c][i] = {"walk": jobs[i].walk, "error": sims[i]["error"]}
    prog = Progress(f"crowd solve ({len(distinct)} fold choices)", len(distinct) * len(ok), stream)
    keys = [(c, i) for c in distinct for i in ok]

    def solved_one(k: int, r: dict[str, Any]) -> None:
        mean_m = (r.get("positions") or {}).get("graph", {}).get("mean_m", math.nan)
        prog.step(f"{r['walk']}: {r['error'] or f'{keys[k][0][0]}, graph mean {mean_m:.1f} m'}")

    walks = [dataclasses.replace(jobs[i], variant=c[0], priors=c[1]) for c, i in keys]
    for (c, i), r in zip(keys, tasks.map(crowd_walk, walks, on_result=solved_one)):
        solved[c][i] = r
    return choice, solved


def fold_stats(
    choice: Choice,
    solved: Mapping[Choice, Mapping[int, Mapping[str, Any]]],
    walk_ids: Sequence[int],
    cell_size_m: float,
) -> dict[int, WalkStats]:
    """Walk index → its crowd-map statistics under ``choice`` (empty for a failed solve)."""
    empty = WalkStats.empty(cell_size_m)
    return {i: solved[choice][i].get("stats", empty) for i in walk_ids}


def choice_doc(c: Choice) -> dict[str, Any]:
    return {"heading_variant": c[0], "priors": dataclasses.asdict(c[1])}
