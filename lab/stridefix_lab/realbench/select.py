"""Per-fold choice of the matcher configuration by cross-validation inside the training walks.

``stridefix-lab realbench`` may learn anything from the other walks of a fold, never from the held-out
one. Some constants cannot be learned in closed form — e.g. whether averaging two consecutive scans
(``fingerprint.average_scans=2``) beats single scans depends on the scan rate, the walking speed and
the map, and which signal representation WkNN should compare (dBm or "powed") depends on the
devices and the building. They are chosen by measuring the candidates on the training walks:

* the walks of a group are dealt into ``n_blocks`` blocks (walk index mod n_blocks);
* for every ordered pair of blocks (a, b), a ≠ b, a radio map is built from the walks outside a and b
  (sufficient statistics: total − block a − block b), and every walk of block b is replayed with it
  through the real ``stridefixd`` (``--fusion wifi_only``) once per candidate;
* the error of each Wi-Fi fix against the truth (linear between waypoints, inside the truth span)
  is pooled per (a, candidate): these are out-of-sample errors on walks other than block a, from maps
  that never saw block a;
* every held-out walk of block a gets the candidate with the lowest pooled mean fix error.

A second stage does the same for the adaptive scheme's Wi-Fi accuracy-factor scale (with block a's
matcher, on the adaptive scheme's POSE error at the waypoints): the AADR 2015 table is on the AP
count, which says little when every scan hears ~100 APs.

So the held-out walk's data never enter its own choice. The candidates and the order of the stages
are rows of :mod:`.tuning` (:data:`~.tuning.AXES`); this module only measures them. Cost: n_blocks·(n_blocks − 1) maps and
(n_blocks − 1) replays of every walk per candidate, fewer where stages share replays:

* one replay serves every stage that asks for the same walk, site and ``--set`` list in the same mode
  (:class:`ReplayCache`, one per group): the adaptive stage's "table x 1" is the matcher's replay with
  block a's matcher, and the fix model's replays are the adaptive stage's with block a's choice;
* the matcher, adaptive and fix-model stages replay in one mode (:data:`MODES`): ``--fusion adaptive``,
  only FIX and POSE written (POSE: the adaptive pose, the primary of a one-scheme replay). ``--fusion`` only picks what is published (the estimator runs every
  scheme either way), and a FIX record's fix fields (t_us, x_m, y_m, accuracy_m) are the fix as
  offered, the same in every scheme's audit (``firmware/core/sf_fusion.c``, ``audit_begin``), so
  the adaptive scheme's FIX rows give the Wi-Fi fix errors that wifi_only's gave. Those replays
  also run a one-particle cloud (``particle.count=1``, after every other setting): neither a fix
  nor the adaptive scheme reads the particle scheme (its cloud is its own state, with its own
  generator), and the cloud was ~40 % of a replay's instructions. The controller scheme's replays
  ("all") score every scheme, the particle scheme too, and keep the cloud.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from stridefix_analyzer import schemes
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.channels import POSE_SCHEME_CHANNELS, table_of
from stridefix_analyzer.io.logread import Table, read_table, read_tables
from stridefix_analyzer.parallel import TaskRunner

#: what each stage replays (--fusion) and scores
STAGES = {"matcher": "wifi_only", "adaptive": "adaptive", "fixmodel": "wifi_only"}
DEFAULT_BLOCKS = 4
#: fewest walks in a group for a choice (fewer: the firmware default)
MIN_WALKS = 6
#: how a stage's replays run (its mode): stridefixd --fusion (None: every scheme), the channels
#: written and settings after the job's own (what the mode does not score, made cheap); "one"
#: replays serve the matcher, adaptive and fix-model stages alike (module text)
MODES: dict[str, tuple[str | None, tuple[str, ...], tuple[str, ...]]] = {
    "one": ("adaptive", ("FIX", "POSE"), ("particle.count=1",)),
    "all": (None, tuple(POSE_SCHEME_CHANNELS.values()), ()),  # each fusion scheme's own poses
}
STAGE_MODE = {"matcher": "one", "adaptive": "one", "fixmodel": "one", "lsd": "all"}
#: the fusion schemes whose POSE errors an "all" replay keeps (the controller is not one)
FUSION_NAMES = tuple(s.name for s in schemes.FUSION_SCHEMES)


def fix_residuals_m(fw_log: str | Path, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> np.ndarray:
    """Every Wi-Fi fix's error against the truth (one row per scan: the schemes repeat it), linear
    between waypoints, fixes outside the truth span left out, in time order: rows (error x [m],
    error y [m], the matcher's accuracy_m [m], distance walked along the truth since its first
    waypoint [m])."""
    return _fix_residuals(read_table(fw_log, "FIX"), wp_t_us, wp_xy_m)


def _fix_residuals(fix: Table | None, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> np.ndarray:
    wp_t_us = np.asarray(wp_t_us, np.int64)
    wp = np.asarray(wp_xy_m, float).reshape(-1, 2)
    if fix is None or not len(fix) or len(wp_t_us) < 2:
        return np.zeros((0, 4))
    t, first = np.unique(fix["t_us"], return_index=True)
    keep = (t >= wp_t_us[0]) & (t <= wp_t_us[-1]) & (fix["accuracy_m"][first] > 0)
    t, first = t[keep], first[keep]
    ex = fix["x_m"][first] - np.interp(t, wp_t_us, wp[:, 0])
    ey = fix["y_m"][first] - np.interp(t, wp_t_us, wp[:, 1])
    walked_m = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(wp, axis=0).T))])
    return np.column_stack([ex, ey, fix["accuracy_m"][first], np.interp(t, wp_t_us, walked_m)])


def fix_errors_m(fw_log: str | Path, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> np.ndarray:
    """2-D error [m] of every Wi-Fi fix of a stridefixd log (one per scan) against the truth
    interpolated linearly between waypoints; fixes outside the truth span are left out."""
    r = fix_residuals_m(fw_log, wp_t_us, wp_xy_m)
    return np.hypot(r[:, 0], r[:, 1])


def pose_errors_m(fw_log: str | Path, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> np.ndarray:
    """2-D error [m] at each waypoint of the latest POSE at or before it (causal, as realbench scores;
    the log holds one scheme); waypoints before the first pose are left out."""
    return _pose_errors(read_table(fw_log, "POSE"), wp_t_us, wp_xy_m)


def _pose_errors(pose: Table | None, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> np.ndarray:
    wp_t_us = np.asarray(wp_t_us, np.int64)
    wp = np.asarray(wp_xy_m, float).reshape(-1, 2)
    if pose is None or not len(pose):
        return np.zeros(0)
    pose = pose.rows(np.isfinite(pose["sigma_m"]) & (pose["sigma_m"] < 1e6))  # initialised only
    k = np.searchsorted(pose["t_us"], wp_t_us, side="right") - 1
    ok = k >= 0
    return np.hypot(pose["x_m"][k[ok]] - wp[ok, 0], pose["y_m"][k[ok]] - wp[ok, 1])


def scheme_pose_errors(pose: Table | None, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> dict[str, np.ndarray]:
    """:func:`pose_errors_m` of every fusion scheme of a POSE table that holds several (by name; a
    scheme without an initialised pose has none)."""
    out: dict[str, np.ndarray] = {}
    if pose is None or not len(pose):
        return out
    pose = pose.rows(np.isfinite(pose["sigma_m"]) & (pose["sigma_m"] < 1e6))
    for code in np.unique(pose["scheme"]):
        name = schemes.scheme_name(int(code))
        if name in FUSION_NAMES:
            out[name] = _pose_errors(pose.rows(pose["scheme"] == code), wp_t_us, wp_xy_m)
    return out


def _firmware_args(job: Mapping[str, Any]) -> dict[str, Any]:
    fusion, channels, cheap = MODES[job["mode"]]
    return {
        "input": f"lcmlog:{job['import_log']}",
        "site": job["site"],
        "fusion": fusion,
        "log": job["log"],
        "sets": [*job["sets"], *cheap],
        "channels": channels,
    }


def _products(job: Mapping[str, Any]) -> dict[str, Any]:
    """The numbers of a finished replay's log (removed after)."""
    # the tables of the channels written (every pose channel reads into POSE)
    tables = read_tables(job["log"], dict.fromkeys(table_of(ch) for ch in MODES[job["mode"]][1]))
    wp = (job["wp_t_us"], job["wp_xy_m"])
    out: dict[str, Any]
    if job["mode"] == "one":
        out = {"fix": _fix_residuals(tables["FIX"], *wp), "pose": _pose_errors(tables["POSE"], *wp)}
    else:
        out = {"schemes": scheme_pose_errors(tables["POSE"], *wp)}
    Path(job["log"]).unlink(missing_ok=True)
    return {"failure": None, **out}


def replay_products(job: dict[str, Any]) -> dict[str, Any]:
    """One inner-CV replay in its mode (:data:`MODES`): ``{"failure": None, ...}`` with, for "one",
    ``fix`` (:func:`fix_residuals_m` rows) and ``pose`` (the adaptive POSE errors at the waypoints,
    :func:`pose_errors_m`), for "all", ``schemes`` (:func:`scheme_pose_errors`); or the end of
    stridefixd's stderr as ``failure``. Only the numbers are kept: the log is removed."""
    proc = Firmware(job["stridefixd"]).run(**_firmware_args(job), check=False)
    if proc.returncode != 0:
        return {"failure": proc.stderr.strip()[-200:]}
    return _products(job)


def replay_batch(jobs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """:func:`replay_products` of every job, in one ``stridefixd --batch`` process (the jobs of a batch
    share their firmware; consecutive jobs mostly share a site, read once). A job whose replay failed
    (or a batch that could not run) is replayed alone, for its own stderr."""
    fw = Firmware(jobs[0]["stridefixd"])
    statuses = fw.run_batch([_firmware_args(j) for j in jobs], Path(jobs[0]["log"]).with_suffix(".batch"))
    return [
        _products(j) if statuses is not None and statuses[k] == 0 else replay_products(j)
        for k, j in enumerate(jobs)
    ]


#: inner-CV replays per stridefixd process (:func:`replay_batch`; chunks of consecutive jobs, mostly
#: of one site)
BATCH = 16


#: what each stage measures on its replay's products (:func:`replay_products`)
SCORES: dict[str, Callable[[dict[str, Any]], Any]] = {
    "matcher": lambda p: np.hypot(p["fix"][:, 0], p["fix"][:, 1]),  # fix_errors_m
    "adaptive": lambda p: p["pose"],
    "fixmodel": lambda p: p["fix"],
    "lsd": lambda p: p["schemes"],
}


@dataclasses.dataclass
class ReplayCache:
    """The products of the inner-CV replays of one group by what went in (mode, walk, import log,
    site, --set list, firmware): a replay that another stage already ran is not run again."""

    products: dict[tuple[Any, ...], dict[str, Any]] = dataclasses.field(default_factory=dict)
    #: the summed statistics of the walks a selection map leaves out, by their indices (every stage
    #: asks for the same block pairs)
    removed: dict[tuple[int, ...], Any] = dataclasses.field(default_factory=dict)
    ran: int = 0  # replays run
    reused: int = 0  # tasks served from an earlier replay

    @staticmethod
    def key(job: Mapping[str, Any]) -> tuple[Any, ...]:
        return (
            job["mode"],
            job["walk"],
            job["import_log"],
            job["site"],
            tuple(job["sets"]),
            job["stridefixd"],
        )

    def run(
        self, jobs: list[dict[str, Any]], runner: TaskRunner, progress: Callable[[], None] | None
    ) -> list[dict[str, Any]]:
        """Every job with its stage's ``errors`` (None on failure) and ``failure``, in job order;
        each replay not run before runs once, on ``runner``."""
        todo: dict[tuple[Any, ...], dict[str, Any]] = {}
        for j in jobs:
            k = self.key(j)
            if k not in self.products and k not in todo:
                todo[k] = j

        def done(_: int, batch: list[dict[str, Any]]) -> None:
            if progress is not None:
                for _r in batch:
                    progress()

        jobs_todo = list(todo.values())
        batches = [jobs_todo[i : i + BATCH] for i in range(0, len(jobs_todo), BATCH)]
        results = [p for r in runner.map(replay_batch, batches, on_result=done) for p in r]
        for k, r in zip(todo, results, strict=True):
            self.products[k] = r
        self.ran += len(todo)
        self.reused += len(jobs) - len(todo)
        out = []
        for j in jobs:
            p = self.products[self.key(j)]
            failed = p["failure"] is not None
            out.append({**j, "errors": None if failed else SCORES[j["stage"]](p), "failure": p["failure"]})
        return out


def block_replays(
    sub: list[dict[str, Any]],
    build_site: Callable[[Any, list[dict[str, Any]], str, Path], list[str] | None] | None,
    *,
    stridefixd: str | Path,
    work_dir: Path,
    base_sets: list[str],
    candidates: dict[str, list[str]],
    tasks: TaskRunner | None,
    n_blocks: int,
    progress: Callable[[], None] | None,
    replay: Callable[[dict[str, Any]], dict[str, Any]] | None,
    stage: str,
    block_sets: Mapping[int, Sequence[str]] | None,
    cache: ReplayCache | None = None,
    site_dir: Path | None = None,
) -> tuple[list[int], list[dict[str, Any]]]:
    """The block of every walk, and the replays of every (a, b ≠ a) block pair for every candidate
    (walks of block b on the map without blocks a and b) in that order, run on ``tasks`` (None: in
    this process; the sites are written here, before any replay, into ``site_dir``, default
    ``work_dir``: every stage of a group passes the same, so one site serves them all; see the module
    text). ``replay`` None: stridefixd through ``cache`` (a new one when None); else
    ``replay(task)`` for every task."""
    block = [i % n_blocks for i in range(len(sub))]
    replays = []
    cache = cache if cache is not None else ReplayCache()
    for a in range(n_blocks):
        for b in range(n_blocks):
            if a == b:
                continue
            inside = tuple(i for i in range(len(sub)) if block[i] in (a, b))
            if inside not in cache.removed:
                cache.removed[inside] = sum((sub[i]["stats"] for i in inside[1:]), sub[inside[0]]["stats"])
            removed = cache.removed[inside]
            others = [sub[i] for i in range(len(sub)) if block[i] not in (a, b)]
            site_path = (site_dir or work_dir) / f"site_{a}_{b}.sfsite"
            assert build_site is not None  # only None when no choice is made (tests)
            site_sets = build_site(removed, others, f"select {a}/{b}", site_path) or []
            for i in (i for i in range(len(sub)) if block[i] == b):
                for name in candidates:
                    sets = [*base_sets, *site_sets, *(block_sets or {}).get(a, []), *candidates[name]]
                    replays.append(
                        {
                            "a": a,
                            "name": name,
                            "walk": sub[i]["walk"],
                            "stage": stage,
                            "mode": STAGE_MODE.get(stage, "one"),
                            "stridefixd": str(stridefixd),
                            "import_log": sub[i]["import_log"],
                            "site": str(site_path),
                            "sets": sets,
                            "log": str(
                                work_dir / f"{stage}_{a}_{b}_{i}_{list(candidates).index(name)}.lcmlog"
                            ),
                            "wp_t_us": sub[i]["waypoint_t_us"],
                            "wp_xy_m": sub[i]["waypoint_xy_m"],
                        }
                    )

    runner = tasks or TaskRunner(None, 1)
    if replay is None:
        return block, cache.run(replays, runner, progress)
    done = (lambda i, r: progress()) if progress else None
    return block, runner.map(replay, replays, on_result=done, chunksize=4)


def select(
    sub: list[dict[str, Any]],
    build_site: Callable[[Any, list[dict[str, Any]], str, Path], list[str] | None] | None,
    *,
    stridefixd: str | Path,
    work_dir: str | Path,
    base_sets: list[str],
    candidates: dict[str, list[str]],
    tasks: TaskRunner | None = None,
    n_blocks: int = DEFAULT_BLOCKS,
    progress: Callable[[], None] | None = None,
    replay: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
    stage: str = "matcher",
    block_sets: Mapping[int, Sequence[str]] | None = None,
    cache: ReplayCache | None = None,
) -> tuple[list[str], dict[str, Any]]:
    """Choose a candidate for every walk of ``sub`` (the prepared walks of one group).

    ``build_site(stats_removed, others, name, path)`` writes to ``path`` the site whose radio map is
    the group's total minus ``stats_removed`` (the summed ``stats`` of the excluded walks), learned
    from the walks ``others`` (map rotation included), and returns the stridefixd settings learned
    from them too (heading variant, stride K) for the replays with that site. ``replay(task) -> task + {"errors", "failure"}`` runs one walk (default:
    stridefixd through ``cache``, the group's :class:`ReplayCache`; on ``tasks``,
    :class:`~stridefix_analyzer.parallel.TaskRunner`, None: in this process, each
    task a pickled copy as a worker gets it). ``stage`` says what is replayed and scored
    (:data:`STAGES`: Wi-Fi fix errors, or the adaptive POSE at the waypoints); ``block_sets[a]`` are
    settings already chosen for block a (its matcher). Returns (the candidate per walk, a report).
    """
    names = list(candidates)
    n_blocks = min(n_blocks, len(sub))
    if len(names) < 2 or len(sub) < MIN_WALKS:
        why = "one candidate" if len(names) < 2 else f"fewer than {MIN_WALKS} walks"
        return [names[0]] * len(sub), {"chosen_by": f"default ({why})", "blocks": {}}
    work_dir = Path(work_dir)
    work_dir.mkdir(parents=True, exist_ok=True)
    block, results = block_replays(
        sub,
        build_site,
        stridefixd=stridefixd,
        work_dir=work_dir,
        base_sets=base_sets,
        candidates=candidates,
        tasks=tasks,
        n_blocks=n_blocks,
        progress=progress,
        replay=replay,
        stage=stage,
        block_sets=block_sets,
        cache=cache,
    )
    pooled: dict[int, dict[str, list[np.ndarray]]] = {a: {n: [] for n in names} for a in range(n_blocks)}
    failures = []
    for r in results:
        if r["errors"] is None:
            failures.append(f"{r['walk']} ({r['name']}): {r['failure']}")
        else:
            pooled[r["a"]][r["name"]].append(r["errors"])
    what = "mean Wi-Fi fix error" if stage == "matcher" else f"mean {STAGES[stage]} error at waypoints"
    report: dict[str, Any] = {
        "chosen_by": f"cross-validation in the training walks ({n_blocks} blocks, {what})",
        "blocks": {},
        "failures": failures[:10],
        "block_of_walk": block,
    }
    choice_of_block, report["blocks"] = choose_per_block(pooled, names, names[0], "fixes")
    report["choice_of_block"] = choice_of_block
    return [choice_of_block[block[i]] for i in range(len(sub))], report


def choose_per_block(
    pooled: Mapping[int, Mapping[str, list[np.ndarray]]], names: Sequence[str], default: str, count_key: str
) -> tuple[dict[int, str], dict[str, Any]]:
    """Per block a of ``pooled`` (block → candidate → error arrays [m]): every candidate's pooled mean
    error and count (under ``count_key``), and the candidate with the lowest finite mean (``default``
    when none has one; ties: the order of ``names``). Returns (choice per block, the blocks' report)."""
    choice: dict[int, str] = {}
    blocks: dict[str, Any] = {}
    for a in pooled:
        means = {}
        for n in names:
            e = np.concatenate(pooled[a][n]) if pooled[a][n] else np.zeros(0)
            means[n] = {"mean_m": float(e.mean()) if len(e) else math.nan, count_key: int(len(e))}
        finite = {n: m["mean_m"] for n, m in means.items() if math.isfinite(m["mean_m"])}
        choice[a] = min(finite, key=lambda n: finite[n]) if finite else default
        blocks[str(a)] = {"candidates": means, "chosen": choice[a]}
    return choice, blocks


def n_tasks(n_walks: int, n_candidates: int, n_blocks: int = DEFAULT_BLOCKS) -> int:
    """Replays :func:`select` will run (for the progress bar)."""
    if n_candidates < 2 or n_walks < MIN_WALKS:
        return 0
    n_blocks = min(n_blocks, n_walks)
    return (n_blocks - 1) * n_walks * n_candidates
