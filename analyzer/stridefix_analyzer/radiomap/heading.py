"""Heading on real walks: how the STEP headings of a replay agree with the truth directions.

Two things are learned from walks with known points (the training walks of a realbench fold, or the
walks ``stridefix site`` builds a site from), both from the same sums
(:func:`rotation_stats`, one set per heading variant the walk was replayed with):

* the map rotation: circular mean of (STEP heading − truth direction) over straight segments
  (:func:`learn_rotation_deg`);
* the heading variant (gait-learned or fixed mounting offset, :data:`HEADING_VARIANTS`): the
  one whose headings agree best with the truth directions once the rotation is taken out
  (:func:`choose_heading_variant`; the heading axis of the lab's realbench tuning).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from stridefix_analyzer.firmware import HEADING_VARIANTS  # noqa: F401 - the heading candidates

#: rotation learning: shortest segment, smallest step-heading resultant length, fewest steps
ROT_MIN_SEGMENT_M = 4.0
ROT_MIN_RESULTANT = 0.95
ROT_MIN_STEPS = 3
RotationSums = dict[str, Any]
"""``sum_cos``, ``sum_sin``, ``n_steps``, ``n_segments``, ``segments`` of one walk (:func:`rotation_stats`)."""


def is_straight(
    segment_m: float, heading_rad: np.ndarray, min_segment_m: float, min_steps: int, min_resultant: float
) -> bool:
    """Whether a segment between two waypoints ``segment_m`` apart was walked straight: at least
    ``min_segment_m`` long, with ``min_steps`` or more steps whose unit headings (``heading_rad``,
    finite) have a resultant length of at least ``min_resultant``."""
    return bool(
        segment_m >= min_segment_m
        and len(heading_rad) >= min_steps
        and np.hypot(np.cos(heading_rad).mean(), np.sin(heading_rad).mean()) >= min_resultant
    )


def rotation_stats(
    step_t_us: ArrayLike,
    step_heading_rad: ArrayLike,
    wp_t_us: ArrayLike,
    wp_xy_m: ArrayLike,
    min_segment_m: float = ROT_MIN_SEGMENT_M,
    min_resultant: float = ROT_MIN_RESULTANT,
    min_steps: int = ROT_MIN_STEPS,
) -> RotationSums:
    """Sums of the heading offset (STEP heading − truth direction) over straight segments.

    A segment is two consecutive waypoints at least ``min_segment_m`` apart whose steps
    (t_k < t ≤ t_{k+1}) number ``min_steps`` or more and point the same way (resultant length of
    their unit heading vectors ≥ ``min_resultant``). Every step of such a segment adds
    ``(cos d, sin d)``, d = heading − atan2(Δy, Δx) of the segment.

    Returns
    -------
    dict
        ``sum_cos``, ``sum_sin``, ``n_steps``, ``n_segments`` (add over walks; the rotation is
        atan2(Σsin, Σcos) [rad]), and ``segments``: per segment (distance walked to its middle along
        the truth [m], its mean heading offset [rad]), for the ekf's bias random walk (the lab's realbench priors).
    """
    step_t_us, h = np.asarray(step_t_us, np.int64), np.asarray(step_heading_rad, float)
    wp_t_us, wp = np.asarray(wp_t_us, np.int64), np.asarray(wp_xy_m, float).reshape(-1, 2)
    out: RotationSums = {"sum_cos": 0.0, "sum_sin": 0.0, "n_steps": 0, "n_segments": 0, "segments": []}
    walked_m = 0.0
    for k in range(len(wp_t_us) - 1):
        seg_start_m = walked_m
        walked_m += float(np.hypot(*(wp[k + 1] - wp[k])))
        d = wp[k + 1] - wp[k]
        if wp_t_us[k + 1] <= wp_t_us[k]:
            continue
        i0, i1 = np.searchsorted(step_t_us, [wp_t_us[k], wp_t_us[k + 1]], side="right")
        hs = h[i0:i1]
        hs = hs[np.isfinite(hs)]
        if not is_straight(float(np.hypot(*d)), hs, min_segment_m, min_steps, min_resultant):
            continue
        off = hs - math.atan2(d[1], d[0])
        out["sum_cos"] += float(np.cos(off).sum())
        out["sum_sin"] += float(np.sin(off).sum())
        out["n_steps"] += int(len(hs))
        out["n_segments"] += 1
        mid_m = 0.5 * (seg_start_m + walked_m)
        out["segments"].append((mid_m, math.atan2(float(np.sin(off).mean()), float(np.cos(off).mean()))))
    return out


def learn_rotation_deg(stats: Sequence[RotationSums], exclude: int | None = None) -> float:
    """Map rotation [deg] (map heading = ENU heading − rotation) from the rotation sums of every
    walk but ``exclude``; NaN when none has a straight segment."""
    c = sum(s["sum_cos"] for j, s in enumerate(stats) if j != exclude)
    s_ = sum(s["sum_sin"] for j, s in enumerate(stats) if j != exclude)
    n = sum(s["n_steps"] for j, s in enumerate(stats) if j != exclude)
    return math.degrees(math.atan2(s_, c)) if n else math.nan


def choose_heading_variant(
    per_walk: Sequence[Mapping[str, RotationSums]], exclude: int | None = None
) -> tuple[str, dict[str, float]]:
    """The variant whose STEP headings agree best with the truth directions over the walks but
    ``exclude``: the largest pooled mean resultant length of (heading − direction), i.e. the
    tightest heading error once the constant part (the map rotation) is taken out. Returns the name
    and the resultant length of every variant (NaN without straight segments)."""
    score = {}
    for name in per_walk[0]:
        c = sum(w[name]["sum_cos"] for j, w in enumerate(per_walk) if j != exclude)
        s_ = sum(w[name]["sum_sin"] for j, w in enumerate(per_walk) if j != exclude)
        n = sum(w[name]["n_steps"] for j, w in enumerate(per_walk) if j != exclude)
        score[name] = math.hypot(c, s_) / n if n else math.nan
    finite = {k: v for k, v in score.items() if math.isfinite(v)}
    best = max(finite, key=lambda k: finite[k]) if finite else next(iter(score))
    return best, score


def learn_heading(
    per_walk: Sequence[Mapping[str, RotationSums]], exclude: int | None = None
) -> tuple[str, dict[str, float], float]:
    """:func:`choose_heading_variant` and the map rotation [deg] of that variant (NaN without
    straight segments), both from the walks but ``exclude``."""
    variant, score = choose_heading_variant(per_walk, exclude)
    return variant, score, learn_rotation_deg([r[variant] for r in per_walk], exclude)
