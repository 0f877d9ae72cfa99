"""The controller's localization scheme descriptor (LSD) of a fold, chosen inside the training walks.

A real-data group is one building floor, so the multi-scheme controller has one context per walk and
its primary pose is the pose of that context's scheme (firmware/core/sf_controller.h). Which fusion
scheme serves a floor best depends on the building, the device and the radio map, so the fold's site
names the scheme that did best on walks other than the held-out one — the site builder's choice, as the
paper's context map names a scheme per context (Jäger et al. §III-C):

* the inner cross-validation of :mod:`.select` (blocks a ≠ b, maps without both, with each block's
  matcher settings) replays every walk of block b ONCE with every scheme running side by side;
* each fusion scheme's POSE error at block b's waypoints (causal, as realbench scores) is pooled per
  block a;
* every held-out walk of block a gets the scheme with the lowest pooled mean error (ties: the
  registry's order).

The selection sites carry the building content the fold sites carry (walls, beacons, geo-reference:
:mod:`.select_sites`), so each scheme is judged with the sources it will have.
Cost: (n_blocks − 1) replays of every walk (one per walk and block pair, not one per scheme).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from stridefix_analyzer.console import Progress
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import read_table
from stridefix_analyzer.parallel import TaskRunner
from stridefix_analyzer.radiomap.contexts import DEFAULT_SCHEME as DEFAULT_CONTEXT_SCHEME

from stridefix_lab.realbench import select as rs

#: the fold's chosen scheme travels with the measured site fields under this key (not a site_t field:
#: run_fold pops it and builds the context map with it)
SITE_KEY = "controller_lsd_scheme"
#: the scheme a fold gets when no choice can be made (fewer walks than the inner CV needs): the
#: site builder's default (radiomap/contexts.py)
DEFAULT_SCHEME = DEFAULT_CONTEXT_SCHEME
#: the candidates: every fusion scheme (the controller itself is not one)
CANDIDATES = rs.FUSION_NAMES


def scheme_pose_errors_m(fw_log: str | Path, wp_t_us: ArrayLike, wp_xy_m: ArrayLike) -> dict[str, np.ndarray]:
    """Per fusion scheme of one stridefixd log: the 2-D error [m] at each waypoint of the scheme's
    latest initialised POSE at or before it (waypoints before its first pose are left out)."""
    return rs.scheme_pose_errors(read_table(fw_log, "POSE"), wp_t_us, wp_xy_m)


def choose_lsd(
    sub: list[dict[str, Any]],
    build_site: Any,
    *,
    firmware: Firmware,
    work_dir: Path,
    base_sets: Sequence[str],
    block_sets: Mapping[int, Sequence[str]],
    tasks: TaskRunner,
    stream: Any,
    n_blocks: int = rs.DEFAULT_BLOCKS,
    cache: rs.ReplayCache | None = None,
    site_dir: Path | None = None,
) -> tuple[list[str], dict[str, Any]]:
    """The scheme of every walk's fold and the group's report (see the module text)."""
    n_blocks = min(n_blocks, len(sub))
    if len(sub) < rs.MIN_WALKS:
        why = f"default {DEFAULT_SCHEME} (fewer than {rs.MIN_WALKS} walks)"
        return [DEFAULT_SCHEME] * len(sub), {"chosen_by": why, "blocks": {}}
    work_dir.mkdir(parents=True, exist_ok=True)
    prog = Progress("choose controller scheme", (n_blocks - 1) * len(sub), stream)
    block, results = rs.block_replays(
        sub,
        build_site,
        stridefixd=firmware.path,
        work_dir=work_dir,
        base_sets=list(base_sets),
        candidates={"all schemes": []},
        tasks=tasks,
        n_blocks=n_blocks,
        progress=prog.step,
        replay=None,
        stage="lsd",
        block_sets=block_sets,
        cache=cache,
        site_dir=site_dir,
    )
    pooled: dict[int, dict[str, list[np.ndarray]]] = {a: {n: [] for n in CANDIDATES} for a in range(n_blocks)}
    failures = []
    for r in results:
        if r["errors"] is None:
            failures.append(f"{r['walk']}: {r['failure']}")
            continue
        for name, e in r["errors"].items():
            pooled[r["a"]][name].append(e)
    choice, blocks = rs.choose_per_block(pooled, CANDIDATES, DEFAULT_SCHEME, "waypoints")
    report: dict[str, Any] = {
        "chosen_by": f"cross-validation in the training walks ({n_blocks} blocks, mean POSE error at "
        "waypoints, every scheme in one replay)",
        "blocks": blocks,
        "failures": failures[:10],
    }
    return [choice[block[i]] for i in range(len(sub))], report
