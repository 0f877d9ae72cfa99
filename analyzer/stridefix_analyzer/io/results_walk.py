"""The typed shape of metrics.json's ``walk``: what ``stridefix analyze`` says of a walk without truth.

Written by :mod:`stridefix_analyzer.scoring.walk` into every analyze metrics.json (kind
``stridefix.analyze.metrics/v1``, :class:`~stridefix_analyzer.io.results.AnalyzeMetrics`): beside
the error keys when the logs held TRUTH (``"truth": true``), alone when they did not (``"truth":
false``; then the error keys are absent and ``primary_scheme``, ``primary_from`` and ``walk`` are
what a reader relies on, :data:`WALK_REQUIRED`). Non-finite numbers are ``null``.
"""

from __future__ import annotations

from typing import TypedDict

#: top-level keys a reader of a metrics.json without truth relies on
WALK_REQUIRED = ("primary_scheme", "walk")


class Consistency(TypedDict):
    # NIS figures of a set of FIX records (the judged ones: accepted, gated, recovered, between floors)
    judged: int
    nis_mean: float | None  # expected 2 (χ², 2 dof)
    within_chi2_95_rate: float | None  # expected 0.95
    accepted_nis_mean: float | None  # cut off at the gate: ≤ gate²


class FixConsistency(Consistency):  # one scheme's fixes (or one source's): counts and consistency.
    offered: int
    accepted: int


class SigmaStats(TypedDict):  # the σ a scheme claims (pose_t.sigma_m) over its poses [m].
    n: int
    median: float | None
    p95: float | None
    max: float | None
    final: float | None


class WalkScheme(TypedDict):  # one scheme's truth-less figures (``walk.per_scheme[scheme]``).
    n_pose: int
    duration_s: float
    track_length_m: float
    floors_visited: list[int]
    sigma_m: SigmaStats
    fixes: FixConsistency
    fixes_by_method: dict[str, FixConsistency]


class ActivityTime(TypedDict):  # steps of one activity and the sum of their periods [s].
    steps: int
    seconds: float


class WalkSteps(TypedDict):
    count: int  # the last STEP index (or the primary pose's step_count without STEP)
    step_messages: int
    walked_m: float | None  # the stride lengths' sum
    cadence_spm: float | None  # steps per minute: 60 / median walking step period
    activity: dict[str, ActivityTime]


class BaroHeight(TypedDict):  # barometric height relative to the first second [m].
    n: int
    min: float | None
    max: float | None
    final: float | None


class HealthGrowth(TypedDict):  # HEALTH over the walk: each integer counter's last − first, where > 0.
    reports: int
    span_s: float | None
    grew: dict[str, int]


class ConsistencyGate(TypedDict):  # how the NIS was derived and what a consistent scheme gives.
    gate_sigma: float
    gate_sigma_from: str
    chi2_dof: int
    chi2_95: float
    expected_nis_mean: float


class WalkMetrics(TypedDict):
    """metrics.json ``walk``: the primary pose's floors, the walk's steps, baro and HEALTH, and every
    scheme's claimed σ and innovation consistency."""

    duration_s: float
    steps: WalkSteps
    floors_visited: list[int]
    floor_changes: int
    barometric_height_m: BaroHeight
    health: HealthGrowth
    consistency: ConsistencyGate
    per_scheme: dict[str, WalkScheme]
