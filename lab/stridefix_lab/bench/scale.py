"""``stridefix-lab bench scale``: realbench and ``radiomap build`` on one msindoor floor, serially and on
Dask (fleets of walks as tasks on a cluster).

Each run is its own process (``stridefix-lab realbench``, ``stridefix radiomap build``: what is timed is the command a user runs) (so a Dask run's wall time includes its LocalCluster's start):

* ``realbench --format msindoor FLOOR --true-start`` (as ``make bench`` runs it) with ``--scheduler
  serial``, ``processes`` (2 forked processes, realbench's default), ``local --workers 1`` and
  ``local --workers 2``, into one folder and one import cache (warmed by a first, untimed run when it
  holds no import yet, so every timed run replays the same cached imports); every results.json must equal the serial one apart from
  the timers and the scheduling record (:func:`~stridefix_lab.realbench.summary.untimed`);
* ``radiomap build`` of the floor's imported walks (the cache's ``*.lcmlog``) with the same schedulers;
  every site file must be byte-identical to the serial one.

Wall times, speed-ups over serial and the machine's load average (a shared machine's runs vary: the
load says how much) go into ``scale.json``, rewritten after every run (a run that is stopped keeps the
ones before it). Not in ``make bench``: site2/F3 (37 walks, the default) took 7 minutes on 2 cores
(81 s of it warming the cache); site1/F2 (102 walks) takes about 25.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.results import read_realbench_results

from stridefix_lab.bench.registry import Bench
from stridefix_lab.realbench.summary import untimed
from stridefix_lab.stages import lab_exe, run_stage, stridefix_exe

DEFAULT_FLOOR = Path("..") / "shared" / "data" / "msindoor" / "site2" / "F3"
#: name → --scheduler options
RUNS = {
    "serial": ["--scheduler", "serial"],
    "processes_2": ["--scheduler", "processes", "--workers", "2"],
    "dask_1": ["--scheduler", "local", "--workers", "1"],
    "dask_2": ["--scheduler", "local", "--workers", "2"],
}


class ScaleBenchError(RuntimeError):
    """A run failed, or gave results that differ from the serial run's."""


def _timed(cmd: list[str], what: str) -> float:
    t = time.perf_counter()
    run_stage(cmd, what, ScaleBenchError)
    return time.perf_counter() - t


def run_scale(
    stridefixd: str | Path, out: Path, floor: Path = DEFAULT_FLOOR, runs: Any = None
) -> dict[str, Any]:
    """Runs the bench (module docstring); returns (and writes ``out/scale.json``) the document."""
    runs = dict(runs or RUNS)
    t0 = time.perf_counter()
    work = out / "scale"
    results, cache = work / "realbench" / "results.json", work / "cache"
    base = [lab_exe(), "realbench", "--format", "msindoor", str(floor), "--true-start", "--quiet"]
    base += ["--no-report", "--stridefixd", str(stridefixd), "--cache", str(cache), "--out", str(results)]
    warm_s = None
    if not any(cache.rglob("*.lcmlog")):
        warm_s = _timed(
            [*base, "--scheduler", "processes", "--workers", "2"], "realbench (warming the cache)"
        )
    realbench: dict[str, Any] = {}
    radiomap: dict[str, Any] = {}
    doc: dict[str, Any] = {
        "floor": str(floor),
        "cpus": os.cpu_count(),
        "realbench": realbench,
        "realbench_warm_s": warm_s,
        "radiomap": radiomap,
    }
    first = None
    for name, opts in runs.items():
        load = os.getloadavg()[0]
        wall_s = _timed([*base, *opts], f"realbench {name}")
        res = read_realbench_results(results)
        first = first or untimed(res)
        realbench[name] = {
            "wall_s": wall_s,
            "run_s": res["run_s"],
            "scheduler": res["params"]["scheduler"],
            "identical": untimed(res) == first,
            "load_1min_before": load,
        }
        _write(out, doc, t0)
    logs = sorted(str(p) for p in cache.rglob("*.lcmlog"))
    doc["walks"] = len(logs)
    site0 = None
    for name, opts in runs.items():
        site = work / "radiomap" / name / "floor.sfsite"  # one file stem: the site's name
        load = os.getloadavg()[0]
        wall_s = _timed(
            [stridefix_exe(), "radiomap", "build", *logs, "--out", str(site), *opts], f"radiomap {name}"
        )
        data = site.read_bytes()
        site0 = site0 or data
        radiomap[name] = {
            "wall_s": wall_s,
            "identical": data == site0,
            "bytes": len(data),
            "load_1min_before": load,
        }
        _write(out, doc, t0)
    return doc


def _write(out: Path, doc: dict[str, Any], t0: float) -> None:
    """``out/scale.json`` of the runs so far (speed-ups, the identity verdict, the time taken)."""
    for table in (doc["realbench"], doc["radiomap"]):
        for r in table.values():
            r["speedup_vs_serial"] = table["serial"]["wall_s"] / r["wall_s"] if "serial" in table else None
    doc["identical"] = all(r["identical"] for t in (doc["realbench"], doc["radiomap"]) for r in t.values())
    doc["run_s"] = time.perf_counter() - t0
    out.mkdir(parents=True, exist_ok=True)
    (out / "scale.json").write_text(json.dumps(doc, indent=1) + "\n")


def format_table(doc: dict[str, Any]) -> str:
    lines = [f"scale: {doc['floor']} ({doc['walks']} walks, {doc['cpus']} CPUs)"]
    lines.append(
        f"  {'run':<14}{'realbench [s]':>15}{'x serial':>10}{'radiomap [s]':>14}{'x serial':>10}{'same':>6}"
    )
    for name, r in doc["realbench"].items():
        m = doc["radiomap"].get(name, {})
        same = r["identical"] and m.get("identical", True)
        lines.append(
            f"  {name:<14}{r['wall_s']:>15.1f}{r['speedup_vs_serial']:>10.2f}"
            f"{m.get('wall_s', float('nan')):>14.1f}{m.get('speedup_vs_serial') or float('nan'):>10.2f}"
            f"{'yes' if same else 'NO':>6}"
        )
    return "\n".join(lines)


def missed_targets(doc: dict[str, Any]) -> list[str]:
    """The one target: every scheduler's results equal the serial run's."""
    return [] if doc["identical"] else ["scale: a Dask or process run differs from the serial run"]


def add_floor_argument(p: argparse.ArgumentParser, of: str = "") -> None:
    """``--floor DIR``: the msindoor floor a bench reads (``of`` says what for, in the help)."""
    p.add_argument(
        "--floor",
        default=str(DEFAULT_FLOOR),
        metavar="DIR",
        help=f"the msindoor floor folder{of} (default {DEFAULT_FLOOR})",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # real walks, no seed
    doc = run_scale(firmware.path, out, Path(args.floor))
    print(format_table(doc))
    print(f"wrote {out / 'scale.json'} ({doc['run_s']:.0f} s)")
    return missed_targets(doc)


BENCH = Bench(
    "scale",
    "realbench and radiomap build on one msindoor floor serially, on 2 processes and on Dask 1 and 2 "
    "workers: wall times and identical results (~25 min, not in make bench)",
    _run,
    add_arguments=add_floor_argument,
)
