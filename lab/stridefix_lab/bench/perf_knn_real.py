"""``stridefix-lab bench perf``'s scikit-learn peer on a real floor: the radio map of a real
msindoor floor, the held-out walks' scans, our matcher and ``KNeighborsRegressor`` side by side.

The floor's walks (sorted by name) are imported once (realbench's importer and cache,
:func:`~stridefix_lab.realbench.walks.cached_import`); every :data:`HOLD_OUT_EVERY`-th walk is held
out, the others build the radio map (:func:`~stridefix_analyzer.radiomap.build.build_site`, the
``stridefix radiomap build`` defaults). The held-out walks' scans, placed on their truth the way a map
build places them (:func:`~stridefix_analyzer.radiomap.placement.collect_scans`, one reading per BSSID
at its strongest), are the queries. The harness ``sf_site_match`` (``tests/perf/site_match.c``) loads
the site file with the board's loader and stridefixd's workspace, matches each scan on its own with
the default parameters (pre-selection, and the full visit), and writes the wifidump text of the map's
WkNN levels and the readings it used; :func:`.perf_peers.compare_knn` then fits scikit-learn on the
same dense fingerprints. So both see the same map and the same queries. Two differences stay, and the
row counts both: the C matcher may refuse a scan (fewer than ``fingerprint.min_aps`` usable APs),
sklearn never does; and the C matcher scores only the RPs that share a used AP with the scan,
sklearn every RP (``same_fix_fraction``: the scans where both fixes coincide).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer.io.sitefile import write_site
from stridefix_analyzer.radiomap.build import build_site
from stridefix_analyzer.radiomap.placement import (
    DEFAULT_SCAN_DURATION_MS,
    DEFAULT_STATIC_TOL_M,
    ap_rows,
    collect_scans,
)
from stridefix_analyzer.radiomap.recordings import load_recordings

from stridefix_lab.bench.perf_peers import compare_knn, read_wifidump
from stridefix_lab.realbench.walks import cached_import, dataset, find_groups
from stridefix_lab.stages import StageError

#: every this-many-th walk of the floor (sorted by name) is held out; the rest build the map
HOLD_OUT_EVERY = 4


def site_match_path(stridefixd: Path) -> Path:
    """``sf_site_match`` of the build tree that holds ``stridefixd`` (``build/firmware/stridefixd``)."""
    return stridefixd.resolve().parents[1] / "tests" / "perf" / "sf_site_match"


def write_queries(recordings: list[Any], path: Path) -> int:
    """The placed scans of ``recordings`` as the harness's query lines; returns how many."""
    placed = collect_scans(recordings, DEFAULT_SCAN_DURATION_MS, DEFAULT_STATIC_TOL_M)
    ok = np.asarray(placed["ok"], bool)
    a_scan, a_bssid, a_rssi, _, _ = ap_rows(placed, ok)
    lines = []
    for i in np.flatnonzero(ok):
        lo, hi = np.searchsorted(a_scan, [i, i + 1])
        readings = " ".join(f"{int(b)} {r:.9g}" for b, r in zip(a_bssid[lo:hi], a_rssi[lo:hi]))
        lines.append(f"q {placed['x_m'][i]:.9g} {placed['y_m'][i]:.9g} {hi - lo} {readings}".rstrip())
    path.write_text("\n".join(lines) + "\n")
    return len(lines)


def _run_harness(harness: Path, site: Path, queries: Path, dump: Path, full: bool) -> dict[str, Any]:
    cmd = [str(harness), str(site), str(queries), str(dump), *(["full"] if full else [])]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise StageError(f"perf peers: {' '.join(cmd)} failed ({proc.returncode}): {proc.stderr[-400:]}")
    return {"summary": json.loads(proc.stdout), "dump": read_wifidump(dump)}


def measure_knn_peer_real(harness: Path, floor: Path, out: Path) -> dict[str, Any]:
    """The peer on the msindoor floor folder ``floor`` (module docstring); ``out`` holds the cache,
    the site file, the queries and the dumps."""
    if not harness.is_file():
        raise StageError(f"perf peers: {harness} not found (build it: make build)")
    ds = dataset("msindoor")
    groups = find_groups(ds, [floor])
    if len(groups) != 1 or len(groups[0].walks) < HOLD_OUT_EVERY:
        raise StageError(f"perf peers: {floor}: not one msindoor floor of >= {HOLD_OUT_EVERY} walks")
    group = groups[0]
    work = out / "perf_knn_real"
    cache = work / "cache"
    cache.mkdir(parents=True, exist_ok=True)
    logs = [cached_import(ds, w, cache, group.options)["out"] for w in group.walks]
    held = [str(log) for i, log in enumerate(logs) if i % HOLD_OUT_EVERY == 0]
    train = [str(log) for i, log in enumerate(logs) if i % HOLD_OUT_EVERY != 0]
    site, summary = build_site(
        load_recordings(train), name=f"{group.label} without every {HOLD_OUT_EVERY}th walk"
    )
    site_path = work / "floor.sfsite"
    write_site(site_path, site)
    queries = work / "queries.txt"
    n_queries = write_queries(load_recordings(held), queries)
    pre = _run_harness(harness, site_path, queries, work / "dump.txt", full=False)
    full = _run_harness(harness, site_path, queries, work / "dump.full.txt", full=True)
    doc = compare_knn(pre, full)
    doc["measured"] = (
        f"msindoor {group.label}: a map of {len(train)} walks ({summary.get('mode', '?')} mode), the {n_queries} "
        f"placed scans of the {len(held)} held-out walks (every {HOLD_OUT_EVERY}th by name), each matched alone "
        "(sf_site_match, default parameters); " + doc["measured"]
    )
    doc["floor"] = group.label
    doc["held_out"] = [Path(h).stem for h in held]
    doc["mean_used_aps"] = pre["summary"]["mean_used"]
    return doc
