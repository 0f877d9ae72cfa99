"""The targets on the real data sets, checked on ``stridefix-lab realbench`` results.

``make bench`` runs ``stridefix-lab realbench`` (every scheme from its first fix, and ``--true-start``) and
``stridefix-lab realbench crowd-map`` on each data set it finds and passes the ``results.json`` files here;
every target is one row of :data:`TARGETS` (data set group, start mode, scheme, metric, bound). A
crowd-map file (``benchmark: crowd-map``) adds its group under ``crowd_map``; its target (start mode
``crowd map``) bounds the crowd-built map's fix error by a factor of the truth-built map's, both from
the same folds. The wall-time budget is a row too (start mode ``wall time``): the fusion
file's ``run_s.total`` (both start modes, every fold and inner selection, on this machine's cores)
per msindoor floor. A group that is not in any file is reported as not run, not as met.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.results import read_any_results
from stridefix_analyzer.schemes import is_fused

from stridefix_lab.bench.registry import Bench


@dataclasses.dataclass(frozen=True)
class Target:
    group: str  # realbench group label ("site1/F2", "gsd/building 100")
    start: str  # "first fix" (summary) or "true start" (summary_true_start)
    scheme: str
    metric: str  # a key of the scheme's summary (mean, p75, ipin_score, floor_hit_rate, ...)
    bound: float
    at_least: bool = False  # the value must reach the bound (floor hit) instead of staying below it
    walk: str = ""  # one walk of the group (its name contains this) instead of the whole group
    #: the bound is this factor times the best fusion scheme's value in the same group and start mode
    #: (the controller against the fixed schemes), not a number of its own
    of_best: bool = False
    #: the bound is this factor times this row's value in the same group and start mode: a scheme
    #: or a textbook reference (``reference_ekf``)
    relative_to: str = ""

    def describe(self) -> str:
        op = ">=" if self.at_least else "<="
        where = f"{self.group}{' ' + self.walk if self.walk else ''}"
        bound = f"{self.bound:g} x best fixed scheme" if self.of_best else f"{self.bound:g}"
        if self.relative_to:
            bound = f"{self.bound:g} x {self.relative_to}"
        if self.start == CROWD_MAP:
            bound = f"{self.bound:g} x truth map"
        if self.start == WALL_TIME:
            return f"{where} realbench fusion wall time [s] {op} {bound}"
        return f"{where} [{self.start}] {self.scheme} {self.metric} {op} {bound}"


#: scheme names of a target that stand for a role: the primary pose (the group's ``summary.primary``)
#: and every fused scheme (the worst of them is held to the bound)
PRIMARY = "primary"
EVERY_FUSED = "every fused scheme"
IPIN2023 = "ipin2023/building 100"

TARGETS: tuple[Target, ...] = (
    # hand-held phones (ipin2023, 25 trials): the primary pose, the fused schemes against Wi-Fi alone and
    # the textbook EKF, floors, and the dead reckoning alone from the true start
    Target(IPIN2023, "first fix", PRIMARY, "ipin_score", 4.0),
    Target(IPIN2023, "first fix", PRIMARY, "ipin_score", 1.0, relative_to="reference_ekf"),
    Target(IPIN2023, "first fix", EVERY_FUSED, "ipin_score", 1.0, relative_to="wifi_only"),
    Target(IPIN2023, "first fix", EVERY_FUSED, "floor_hit_rate", 0.99, at_least=True),
    Target(IPIN2023, "true start", "pdr_only", "mean", 5.0),
    Target(IPIN2023, "true start", "pdr_only", "walks_mean_over_15m", 0.0),
    Target("site2/F3", "first fix", PRIMARY, "mean", 1.02, of_best=True),
    Target("site1/F2", "first fix", "ekf", "mean", 3.5),
    Target("site1/F2", "first fix", "ekf", "p75", 4.5),
    Target("site2/F3", "first fix", "ekf", "mean", 10.0),
    Target("gsd/building 100", "first fix", "ekf", "ipin_score", 4.5),
    Target("gsd/building 100", "true start", "pdr_only", "mean", 6.0),
    # the trial that changes floors (0 → −1 → −2 and back)
    Target("gsd/building 100", "first fix", "ekf", "floor_hit_rate", 0.99, at_least=True, walk="Trial51"),
    # the map-aware particle filter with walls, BLE and GNSS
    Target("site1/F2", "first fix", "particle", "mean", 3.0),
    Target("site1/F2", "first fix", "particle", "p75", 4.0),
    Target("site2/F3", "first fix", "particle", "mean", 8.0),
    Target("gsd/building 100", "first fix", "particle", "ipin_score", 4.0),
    # one context per walk, so the controller must be as good as the best fixed scheme
    Target("site1/F2", "first fix", "controller", "mean", 1.02, of_best=True),
    Target("gsd/building 100", "first fix", "controller", "mean", 1.02, of_best=True),
    # the Wi-Fi fix on a map built from crowd walks (anchors every 4th waypoint, no survey)
    # within 15 % of the one on the surveyed map, same folds (`realbench crowd-map`)
    Target("site1/F2", "crowd map", "wifi_only", "mean", 1.15),
    # realbench (fusion, --true-start) <= 60 s per msindoor floor, by wall clock
    Target("site1/F2", "wall time", "all", "run_s", 60.0),
    Target("site2/F3", "wall time", "all", "run_s", 60.0),
)
#: what the controller is compared with: the fusion schemes, not itself
_NOT_FIXED = ("controller",)

#: the start mode of the crowd-map targets: the value is the crowd-built map's, the bound a factor of the
#: truth-built map's (``realbench crowd-map``, first fix)
CROWD_MAP = "crowd map"
#: the start mode of the wall-time targets: the value is the fusion results file's ``run_s.total`` [s]
WALL_TIME = "wall time"
_SUMMARY = {"first fix": "summary", "true start": "summary_true_start"}
_WALK = {"first fix": "fixes", "true start": "true_start"}


def _crowd_map_value(group: dict[str, Any], t: Target, which: str) -> float:
    """``which`` (truth_map, crowd_map) of the group's crowd-map summary, or NaN."""
    summary = (group.get("crowd_map") or {}).get("summary") or {}
    value = ((summary.get(which) or {}).get(t.scheme) or {}).get(t.metric)
    return float(value) if value is not None else math.nan


def _bound(group: dict[str, Any], t: Target) -> float:
    """The target's bound: its own, its factor times the best fixed scheme's value, or (crowd map)
    its factor times the truth-built map's."""
    if t.start == CROWD_MAP:
        return t.bound * _crowd_map_value(group, t, "truth_map")
    if t.relative_to:
        return t.bound * _row_value(group, t.start, t.relative_to, t.metric)
    if not t.of_best:
        return t.bound
    schemes = (group.get(_SUMMARY[t.start]) or {}).get("schemes") or {}
    values = [
        float(v[t.metric])
        for name, v in schemes.items()
        if name not in _NOT_FIXED and isinstance(v, dict) and v.get(t.metric) is not None
    ]
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return math.nan
    return t.bound * (max(finite) if t.at_least else min(finite))


def _row_value(group: dict[str, Any], start: str, name: str, metric: str) -> float:
    """A scheme's or a reference's summary value in a group and start mode, or NaN."""
    summary = group.get(_SUMMARY[start]) or {}
    row = (summary.get("schemes") or {}).get(name) or (summary.get("references") or {}).get(name) or {}
    value = row.get(metric)
    return float(value) if value is not None else math.nan


def _resolve(group: dict[str, Any], t: Target) -> list[str]:
    """The scheme(s) a target holds: the primary's name, every fused scheme, or its own."""
    summary = group.get(_SUMMARY.get(t.start, "summary")) or {}
    if t.scheme == PRIMARY:
        name = (summary.get("primary") or {}).get("scheme")
        return [name] if name else []
    if t.scheme == EVERY_FUSED:
        return [n for n in (summary.get("schemes") or {}) if is_fused(n)]
    return [t.scheme]


def _value(group: dict[str, Any], t: Target) -> float:
    if t.scheme in (PRIMARY, EVERY_FUSED):
        values = [_row_value(group, t.start, n, t.metric) for n in _resolve(group, t)]
        finite = [v for v in values if math.isfinite(v)]
        if len(finite) != len(values) or not finite:
            return math.nan
        return min(finite) if t.at_least else max(finite)  # the worst of them
    if t.start == CROWD_MAP:
        return _crowd_map_value(group, t, "crowd_map")
    if t.start == WALL_TIME:
        total = group.get("run_s_total")
        return float(total) if total is not None else math.nan
    if t.walk:
        rows = [r for r in group.get("walk_rows") or [] if t.walk in str(r.get("walk"))]
        scheme = ((rows[0].get(_WALK[t.start]) or {}).get(t.scheme) or {}) if len(rows) == 1 else {}
    else:
        scheme = ((group.get(_SUMMARY[t.start]) or {}).get("schemes") or {}).get(t.scheme) or {}
    value = scheme.get(t.metric)
    return float(value) if value is not None else math.nan


class ResultsError(ValueError):
    """A results file that cannot be read as realbench output; the message names it."""


def load_groups(paths: Iterable[str | Path]) -> dict[str, dict[str, Any]]:
    """Group label → group record over every realbench ``results.json`` (a crowd-map file's group
    under the record's ``crowd_map``; a fusion file's ``run_s.total`` as ``run_s_total`` of each of
    its groups)."""
    groups: dict[str, dict[str, Any]] = {}
    for path in paths:
        try:
            run = read_any_results(path)
            if run.crowd_map is not None:
                for c in run.crowd_map["groups"]:
                    groups[c["label"]] = {**groups.get(c["label"], {}), "crowd_map": c}
            elif run.realbench is not None:
                total = (run.realbench.get("run_s") or {}).get("total")
                for g in run.realbench["groups"]:
                    old = groups.get(g["label"], {})
                    groups[g["label"]] = {
                        **g,
                        **({"crowd_map": old["crowd_map"]} if "crowd_map" in old else {}),
                        **({"run_s_total": float(total)} if total is not None else {}),
                    }
            else:
                raise ValueError(f"kind {run.kind!r}")
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ResultsError(f"{path}: not a realbench results file ({exc})") from exc
    return groups


def check(
    groups: dict[str, dict[str, Any]], targets: Sequence[Target] = TARGETS
) -> tuple[list[dict[str, Any]], list[str]]:
    """Every target's row (value, met) and the ``TARGET MISSED`` lines (misses and targets not run)."""
    rows, missed = [], []
    for t in targets:
        group = groups.get(t.group) or {}
        value, bound = _value(group, t), _bound(group, t)
        met = (
            math.isfinite(value)
            and math.isfinite(bound)
            and (value >= bound if t.at_least else value <= bound)
        )
        row = {"target": t.describe(), "value": value, "bound": bound, "met": met}
        if t.start == CROWD_MAP:  # both numbers: the crowd-built map's and the truth-built map's
            row["truth_map"] = _crowd_map_value(group, t, "truth_map")
        rows.append(row)
        if not math.isfinite(value):
            missed.append(f"realbench {t.describe()}: not run")
        elif not met:
            missed.append(f"realbench {t.describe()}: {value:.3g} (bound {bound:.3g})")
    return rows, missed


def format_table(rows: Sequence[dict[str, Any]]) -> str:
    lines = [f"{'target':<84} {'value':>8} {'bound':>8}  met"]
    lines += [
        f"{r['target']:<84} {r['value']:>8.3g} {r.get('bound', math.nan):>8.3g}  {'yes' if r['met'] else 'NO'}"
        + (f"  (crowd map {r['value']:.3g} m, truth map {r['truth_map']:.3g} m)" if "truth_map" in r else "")
        for r in rows
    ]
    return "\n".join(lines)


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--results",
        nargs="*",
        default=[],
        metavar="results.json",
        help="the realbench results files to check (run with --true-start)",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del firmware, seeds  # the replays were realbench's
    rows, missed = check(load_groups(args.results))
    print(format_table(rows))
    out.mkdir(parents=True, exist_ok=True)
    (out / "real_targets.json").write_text(
        json.dumps({"results": list(args.results), "targets": rows}, indent=1)
    )
    print(f"wrote {out / 'real_targets.json'}")
    return missed


BENCH = Bench(
    "real-targets",
    "the real-data targets on realbench results.json files (--results)",
    _run,
    add_arguments=_add_arguments,
    needs_firmware=False,
)
