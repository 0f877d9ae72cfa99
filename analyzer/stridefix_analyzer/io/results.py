"""The result files of the analyzer, typed: realbench's ``results.json`` and analyze's ``metrics.json``.

Every result file says what it is in its first key, ``kind``: :data:`REALBENCH_RESULTS_KIND`
(``realbench [fusion]``, :class:`RealbenchResults`), :data:`CROWD_MAP_RESULTS_KIND` (``realbench
crowd-map``, :class:`CrowdMapResults`: groups pair a truth-built and a crowd-built map) and
:data:`ANALYZE_METRICS_KIND` (``analyze``'s metrics.json, :class:`AnalyzeMetrics`; its ``walk``:
:mod:`.results_walk`). TypedDicts: a document read is the JSON object itself; non-finite numbers are
``null``, hence ``float | None``; blobs shaped by other modules stay dicts. Writers stamp the kind
(``write_*``); readers (``read_*``, :func:`read_any_results`) refuse another kind with a
:class:`ResultsFileError` naming the file, its kind and the one expected, and read a file without
``kind`` as v1 of the kind its shape says.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping
from typing import Any, NotRequired, TypedDict, cast

from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.io.results_errors import NotAResultsFileError
from stridefix_analyzer.io.results_errors import ResultsFileError as ResultsFileError
from stridefix_analyzer.io.results_walk import WALK_REQUIRED, WalkMetrics

#: the ``kind`` of realbench fusion's results.json, of realbench crowd-map's, of analyze's metrics.json
REALBENCH_RESULTS_KIND = "stridefix.realbench.results/v1"
CROWD_MAP_RESULTS_KIND = "stridefix.realbench.crowd-map/v1"
ANALYZE_METRICS_KIND = "stridefix.analyze.metrics/v1"
#: the ``benchmark`` of a crowd-map results.json (what tells a file without ``kind`` apart)
CROWD_MAP_BENCHMARK = "crowd-map"

_WHAT = {
    REALBENCH_RESULTS_KIND: "a realbench fusion results.json",
    CROWD_MAP_RESULTS_KIND: "a realbench crowd-map results.json",
    ANALYZE_METRICS_KIND: "an analyze metrics.json",
}


# --- shared pieces --------------------------------------------------------------------------------


class ErrorStats(TypedDict):
    # Position error statistics [m] of the scored samples (``null`` when none was scored).
    n: int
    mean: float | None
    median: float | None
    p75: float | None
    p90: float | None
    p95: float | None
    max: float | None
    rmse: float | None


class MethodCounts(TypedDict):  # FIX records of one scheme and one method (Wi-Fi, GNSS, BLE, landmark).
    offered: int
    accepted: int
    rejected: int
    rejected_by_reason: dict[str, int]


#: scheme → method → its FIX counts (:mod:`stridefix_analyzer.scoring.fixsources`)
FixSourceCounts = dict[str, dict[str, MethodCounts]]


class FirmwareInfo(TypedDict):  # the stridefixd a realbench run replayed with.
    path: str
    version: str | None


class WalkFailure(TypedDict):  # a walk that could not be prepared or scored, and why.
    walk: str
    error: str | None


# --- realbench fusion: results.json ---------------------------------------------------------------


class WalkScore(ErrorStats):
    # One scheme (or textbook reference) on one walk (``walk_rows[].fixes[scheme]``).
    unscored: int
    floor_hit_rate: float | None
    ipin_score: float | None
    iso18305: dict[str, Any]


class PooledRow(ErrorStats):
    # One scheme (or reference) pooled over a group's walks (``summary.schemes[scheme]``).
    ipin_score: float | None
    floor_hit_rate: float | None
    walks: int
    walks_mean_over_15m: int
    share_walks_mean_over_15m: float | None
    walk_mean_median: float | None


class LostMetric(TypedDict):  # a metric a scheme loses on: its value and its reference's.
    scheme: float | None
    reference: float | None


class Loss(TypedDict):  # a scheme worse than its textbook reference on every metric of ``lost``.
    scheme: str
    reference: str
    lost: dict[str, LostMetric]


class PrimaryPose(TypedDict):
    # The scheme POSE carried in a group and, for the controller, what it followed in how many folds.
    scheme: str | None
    follows: dict[str, int]


class GroupSummary(TypedDict):
    # A group's schemes and references pooled over its walks (``summary``, ``summary_true_start``).
    schemes: dict[str, PooledRow]
    adaptive_vs_wifi_only_reduction_pct: float | None
    references: dict[str, PooledRow]
    loses_to_reference: list[Loss]
    primary: PrimaryPose


class Spread(TypedDict):  # a fold constant over a group's folds.
    n: int
    mean: float | None
    std: float | None
    min: float | None
    max: float | None


class FoldConstants(TypedDict):
    # The constants learnt per fold, spread over a group. The file also holds, per tuning axis,
    # ``<axis>_variant``: variant → number of folds (names not known here).
    K: Spread
    rotation_deg: Spread
    n_rp: Spread
    n_ap: Spread


class WalkRow(TypedDict):
    # One walk of a group: its fold's constants and per scheme its scores (per start mode).
    walk: str
    error: str | None
    fold: dict[str, Any] | None
    rotation_learned: bool
    waypoints: int
    steps_nosite: int
    duration_s: float | None
    floors: Any
    dir: str
    fixes: NotRequired[dict[str, WalkScore]]
    true_start: NotRequired[dict[str, WalkScore]]
    #: start mode (fixes, true_start) → reference name → its scores
    references: dict[str, dict[str, WalkScore]]
    fix_sources: FixSourceCounts


class FusionGroup(TypedDict):
    # One group (a floor, a building) of a fusion run. The file also holds the tuning rows' record
    # of how they chose (e.g. ``heading_variant_all_walks``; names not known here).
    label: str
    walks: int
    ran: int
    failed: list[WalkFailure]
    floor_dir: str | None
    K_all_walks: NotRequired[float | None]
    site_content: NotRequired[dict[str, Any]]
    summary: GroupSummary
    summary_true_start: NotRequired[GroupSummary]
    fold_errors: list[WalkFailure]
    fix_sources: FixSourceCounts
    fix_sources_true_start: NotRequired[FixSourceCounts]
    constants: FoldConstants
    walk_rows: list[WalkRow]


class RealbenchParams(TypedDict):
    # How a fusion run was set up (``jobs`` and ``scheduler`` say how it ran, not what it gave).
    cell_size_m: float
    min_count: int
    firmware_sets: list[str]
    max_wifi_age_s: float | None
    limit: int | None
    jobs: int
    scheduler: str
    robust_mean_m: float
    ipin_floor_penalty_m: float
    rotation: dict[str, float]
    default_storey_m: float
    site_content: dict[str, Any]


class FusionRunTimes(TypedDict):  # wall-clock seconds of a fusion run's phases.
    prepare: float
    folds: float
    total: float


class RealbenchResults(TypedDict):
    """``stridefix-lab realbench [fusion]``'s results.json (:mod:`stridefix_lab.realbench.summary`)."""

    kind: NotRequired[str]  # REALBENCH_RESULTS_KIND; absent in files written before it
    benchmark: str
    format: str
    inputs: list[str]
    true_start: bool
    groups: list[FusionGroup]
    params: RealbenchParams
    stridefixd: FirmwareInfo
    run_s: FusionRunTimes
    report: NotRequired[str]


# --- realbench crowd-map: results.json ------------------------------------------------------------


class PositionError(TypedDict):  # mean position error [m] of the crowd positions over ``n`` waypoints.
    n: int
    mean_m: float | None


class CrowdMapSummary(TypedDict):
    # A group's walks scored on both maps, pooled as realbench fusion pools them.
    truth_map: dict[str, PooledRow]
    crowd_map: dict[str, PooledRow]
    #: scheme → crowd map's mean / truth map's mean
    ratio: dict[str, float | None]
    #: graph (solved) and interpolated crowd positions
    crowd_positions: dict[str, PositionError]


class CrowdMapWalkRow(TypedDict):
    # One walk replayed on the truth-built and on the crowd-built map of its fold.
    walk: str
    error: str | None
    truth_map: dict[str, ErrorStats]
    crowd_map: dict[str, ErrorStats]
    sites: dict[str, dict[str, Any]]
    crowd_rows: dict[str, int] | None
    crowd_positions: dict[str, Any] | None
    crowd_choice: dict[str, Any] | None
    ratio: dict[str, float | None]


class CrowdMapGroup(TypedDict):  # one group of a crowd-map run.
    label: str
    walks: int | None
    ran: int | None
    failed: list[WalkFailure] | None
    paired: int
    crowd_failed: list[WalkFailure]
    crowd_rows: dict[str, int]
    crowd_scans_dropped_uncertain: int
    crowd_heading_variants: dict[str, int]
    summary: CrowdMapSummary
    walk_rows: list[CrowdMapWalkRow]


class CrowdMapRunTimes(TypedDict):  # wall-clock seconds of a crowd-map run's phases.
    prepare_plan: float
    crowd_solve: float
    folds: float
    total: float


class CrowdMapResults(TypedDict):
    """``stridefix-lab realbench crowd-map``'s results.json (:mod:`stridefix_lab.realbench.crowdmap`)."""

    kind: NotRequired[str]  # CROWD_MAP_RESULTS_KIND; absent in files written before it
    benchmark: str  # CROWD_MAP_BENCHMARK
    format: str
    dirs: list[str]
    anchors: str
    solver: str
    max_sigma_m: float | None  # null: no limit
    inputs: str
    crowd_choices: int
    params: dict[str, Any]
    stridefixd: FirmwareInfo
    groups: list[CrowdMapGroup]
    run_s: CrowdMapRunTimes


# --- analyze: metrics.json ------------------------------------------------------------------------


class PositionErrorStats(ErrorStats):  # a scheme's position error [m], and the non-finite errors left out.
    nonfinite: int


class HeadingError(TypedDict):  # heading error [deg] at the scored samples.
    n: int
    rms_deg: float | None
    mean_abs_deg: float | None


class StepCounts(TypedDict):  # steps detected against the truth's (``truth``, ``error`` null without them).
    detected: int
    step_messages: int
    truth: int | None
    error: int | None
    error_pct: float | None


class SchemeMetrics(TypedDict):  # one POSE scheme scored against TRUTH (``per_scheme[scheme]``).
    n_pose: int
    position_error_m: PositionErrorStats
    unscored: int
    floor_hit_rate: float | None
    ipin_score: float | None
    iso18305: dict[str, Any]
    within_1sigma_rate: float | None
    heading_error: HeadingError
    steps: StepCounts
    final_error_m: float | None
    final_error_pct_of_distance: float | None
    wall_crossings: NotRequired[int]  # the site's walls its POSE track passes through (--site with walls)


class AnalyzeMetrics(TypedDict):
    """``stridefix analyze``'s metrics.json (:mod:`stridefix_analyzer.scoring.analyze`): the primary
    scheme's numbers at the top level, every scheme's under ``per_scheme``, and what the logs held;
    ``walk`` its truth-less figures (:mod:`.results_walk`)."""

    kind: NotRequired[str]  # ANALYZE_METRICS_KIND; absent in files written before it
    label: str | None
    inputs: list[dict[str, Any]]
    primary_scheme: str
    primary_from: NotRequired[str]  # pose_channel, requested, fallback (scoring.primary)
    truth: NotRequired[bool]  # false: no TRUTH; then the keys up to per_scheme are absent
    walk: NotRequired[WalkMetrics]
    position_error_m: PositionErrorStats
    unscored: int
    n_truth: int
    floor_hit_rate: float | None
    ipin_score: float | None
    iso18305: dict[str, Any]
    floor_heights: str | None
    floors_in_truth: list[int]
    within_1sigma_rate: float | None
    heading_error: HeadingError
    steps: StepCounts
    distance_walked_m: float
    final_error_m: float | None
    final_error_pct_of_distance: float | None
    per_scheme: dict[str, SchemeMetrics]
    truth_wall_crossings: NotRequired[int]  # the same count for the truth (--site with walls)
    messages: dict[str, int]
    unknown_channels: Any
    decode_errors: Any
    health: dict[str, Any] | None
    fix_sources: FixSourceCounts
    context: dict[str, Any] | None
    config: dict[str, Any]
    warnings: list[str]


# --- writing --------------------------------------------------------------------------------------


def _write(path: str | os.PathLike[str], kind: str, doc: Mapping[str, Any], indent: int) -> dict[str, Any]:
    """Write ``doc`` as JSON values with ``kind`` as its first key (replacing a ``kind`` in it); return
    what was written."""
    out = {"kind": kind, **{k: v for k, v in json_ready(dict(doc)).items() if k != "kind"}}
    with open(path, "w", encoding="utf-8") as f:
        json.dump(out, f, indent=indent, allow_nan=False)
        f.write("\n")
    return out


def write_realbench_results(path: str | os.PathLike[str], doc: Mapping[str, Any]) -> RealbenchResults:
    """Write a fusion run's results.json, stamped :data:`REALBENCH_RESULTS_KIND`; return what was written."""
    return cast(RealbenchResults, _write(path, REALBENCH_RESULTS_KIND, doc, indent=1))


def write_crowd_map_results(path: str | os.PathLike[str], doc: Mapping[str, Any]) -> CrowdMapResults:
    """Write a crowd-map run's results.json, stamped :data:`CROWD_MAP_RESULTS_KIND`."""
    return cast(CrowdMapResults, _write(path, CROWD_MAP_RESULTS_KIND, doc, indent=1))


def write_analyze_metrics(path: str | os.PathLike[str], doc: Mapping[str, Any]) -> AnalyzeMetrics:
    """Write analyze's metrics.json, stamped :data:`ANALYZE_METRICS_KIND`."""
    return cast(AnalyzeMetrics, _write(path, ANALYZE_METRICS_KIND, doc, indent=2))


# --- reading --------------------------------------------------------------------------------------


def _load(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The JSON object of ``path``; :class:`ResultsFileError` naming the file otherwise."""
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except OSError as exc:
        raise ResultsFileError(f"{os.fspath(path)}: cannot read: {exc.strerror or exc}") from exc
    except ValueError as exc:  # UnicodeDecodeError, JSONDecodeError, a 5000-digit number
        raise NotAResultsFileError(f"{os.fspath(path)}: nothing valid in the input: not JSON: {exc}") from exc
    if not isinstance(doc, dict):
        raise ResultsFileError(
            f"{os.fspath(path)}: not a result file (a JSON {type(doc).__name__}, not an object)"
        )
    return doc


def kind_of(doc: Mapping[str, Any]) -> str | None:
    """The kind a result document is: its ``kind``, else (written before the kinds) the v1 kind its
    shape says, else None."""
    kind = doc.get("kind")
    if kind is not None:
        return str(kind)
    if isinstance(doc.get("groups"), list):
        crowd = doc.get("benchmark") == CROWD_MAP_BENCHMARK
        return CROWD_MAP_RESULTS_KIND if crowd else REALBENCH_RESULTS_KIND
    if isinstance(doc.get("per_scheme"), dict):
        return ANALYZE_METRICS_KIND
    return None


#: top-level keys a reader relies on, per kind
_REQUIRED = {
    REALBENCH_RESULTS_KIND: ("groups",),
    CROWD_MAP_RESULTS_KIND: ("groups",),
    ANALYZE_METRICS_KIND: ("per_scheme", "primary_scheme", "position_error_m"),
}


def _checked(path: str | os.PathLike[str], doc: dict[str, Any], expected: str) -> dict[str, Any]:
    """``doc`` when it is of kind ``expected`` (or has no kind and that shape); else the error."""
    name = os.fspath(path)
    kind = kind_of(doc)
    if kind != expected:
        got = f"kind {kind!r}" if "kind" in doc else f"no 'kind', shaped as {kind!r}"
        got = "no 'kind' and not the shape of a result file" if kind is None else got
        what = f" ({_WHAT[kind]})" if kind in _WHAT else ""
        raise ResultsFileError(f"{name}: {got}{what}; expected {expected!r} ({_WHAT[expected]})")
    required = WALK_REQUIRED if doc.get("truth") is False else _REQUIRED[expected]  # truth-less analyze
    missing = [k for k in required if k not in doc]
    if missing:
        raise ResultsFileError(f"{name}: {_WHAT[expected]} without {', '.join(missing)}")
    return doc


def read_realbench_results(path: str | os.PathLike[str]) -> RealbenchResults:
    """A realbench fusion results.json (:data:`REALBENCH_RESULTS_KIND`, or no kind: v1)."""
    return cast(RealbenchResults, _checked(path, _load(path), REALBENCH_RESULTS_KIND))


def read_crowd_map_results(path: str | os.PathLike[str]) -> CrowdMapResults:
    """A realbench crowd-map results.json (:data:`CROWD_MAP_RESULTS_KIND`, or no kind: v1)."""
    return cast(CrowdMapResults, _checked(path, _load(path), CROWD_MAP_RESULTS_KIND))


def read_analyze_metrics(path: str | os.PathLike[str]) -> AnalyzeMetrics:
    """An analyze metrics.json (:data:`ANALYZE_METRICS_KIND`, or no kind: v1)."""
    return cast(AnalyzeMetrics, _checked(path, _load(path), ANALYZE_METRICS_KIND))


@dataclasses.dataclass(frozen=True)
class AnyResults:
    """A result file of any of the three kinds: exactly one of the documents is set."""

    path: str
    kind: str
    realbench: RealbenchResults | None = None
    crowd_map: CrowdMapResults | None = None
    metrics: AnalyzeMetrics | None = None


def read_any_results(path: str | os.PathLike[str]) -> AnyResults:
    """A realbench fusion or crowd-map results.json or an analyze metrics.json, by its kind (or, without
    one, its shape); :class:`ResultsFileError` for anything else."""
    name = os.fspath(path)
    doc = _load(path)
    kind = kind_of(doc)
    if kind not in _WHAT:
        known = ", ".join(repr(k) for k in _WHAT)
        got = f"kind {kind!r}" if "kind" in doc else "no 'kind' and neither groups nor per_scheme"
        raise ResultsFileError(f"{name}: {got}; expected one of {known}")
    doc = _checked(path, doc, kind)
    if kind == REALBENCH_RESULTS_KIND:
        return AnyResults(name, kind, realbench=cast(RealbenchResults, doc))
    if kind == CROWD_MAP_RESULTS_KIND:
        return AnyResults(name, kind, crowd_map=cast(CrowdMapResults, doc))
    return AnyResults(name, kind, metrics=cast(AnalyzeMetrics, doc))


#: the start modes of a walk row and group: every scheme from its first fix, truth-initialised
START_MODES = ("fixes", "true_start")


def walk_scores(row: WalkRow, start: str) -> dict[str, WalkScore]:
    """A walk row's scores per scheme in start mode ``start`` (:data:`START_MODES`); {} when that
    mode did not run (or the walk failed)."""
    if start in START_MODES:
        return cast(dict[str, WalkScore], row.get(start, {}))
    raise ValueError(f"start mode {start!r} not one of {START_MODES}")
