"""The ``ekf`` scheme's start priors from the training walks of a fold: how far one walk's heading and
stride are off what the fold learnt from all of them.

realbench takes the map rotation (the mean heading offset) and Weinberg's K (the mean stride) from the
other walks; what is left for the held-out walk is its own offset from those means. Its spread over
the training walks is the prior the ``ekf`` should start with (``firmware/core/sf_ekf.h``), instead
of the firmware's "unknown" defaults, which fit a unit in the field that has no training walks:

* ``ekf.init_bias_sigma_rad``: the circular standard deviation √(−2 ln R̄) of the per-walk heading
  offsets (STEP heading − truth direction over straight segments, :func:`stridefix_analyzer.radiomap.heading.rotation_stats`),
  R̄ the mean resultant length of one unit vector per walk;
* ``ekf.init_scale_sigma``: the relative standard deviation of the per-walk K (Σ true distance /
  Σ Weinberg term over the walk's scored segments);
* ``ekf.bias_rw_rad2_per_m``: how fast the heading offset wanders within a walk: the mean squared
  change of the offset between consecutive straight segments of a walk over the mean distance between
  them (a random walk per metre; segments at most :data:`MAX_SEGMENT_GAP_M` apart).

Each needs :data:`MIN_WALKS` training walks with data, else the firmware default stays.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

#: fewest training walks with data for a prior
MIN_WALKS = 3
#: the priors are kept in these ranges: below, a walk's own noise dominates; above, it is unknown
BIAS_SIGMA_RANGE_RAD = (0.02, 1.0)
SCALE_SIGMA_RANGE = (0.01, 0.5)
BIAS_RW_RANGE_RAD2_PER_M = (1e-4, 0.05)
#: consecutive straight segments further apart than this do not enter the bias random walk [m]
MAX_SEGMENT_GAP_M = 40.0
#: fewest segment pairs for the random walk
MIN_SEGMENT_PAIRS = 10


def bias_rw_rad2_per_m(rotation: Sequence[Mapping[str, Any]], exclude: int) -> float:
    """Σ Δoffset² / Σ Δs over consecutive straight segments of every walk but ``exclude`` (NaN: too few)."""
    sq, gap, n = 0.0, 0.0, 0
    for j, r in enumerate(rotation):
        segs = r.get("segments") or []
        if j == exclude:
            continue
        for (s0, o0), (s1, o1) in zip(segs[:-1], segs[1:]):
            if 0.0 < s1 - s0 <= MAX_SEGMENT_GAP_M:
                d = math.atan2(math.sin(o1 - o0), math.cos(o1 - o0))
                sq, gap, n = sq + d * d, gap + (s1 - s0), n + 1
    return sq / gap if n >= MIN_SEGMENT_PAIRS and gap > 0 else math.nan


def heading_bias_sigma_rad(rotation: Sequence[Mapping[str, Any]], exclude: int) -> float:
    """Circular σ of the per-walk heading offsets of every walk but ``exclude`` (NaN: too few)."""
    units = [
        (r["sum_cos"], r["sum_sin"])
        for j, r in enumerate(rotation)
        if j != exclude and r["n_steps"] > 0 and math.hypot(r["sum_cos"], r["sum_sin"]) > 0
    ]
    if len(units) < MIN_WALKS:
        return math.nan
    u = np.array([(c / math.hypot(c, s), s / math.hypot(c, s)) for c, s in units])
    resultant = float(np.hypot(*u.mean(axis=0)))
    return math.sqrt(-2.0 * math.log(max(resultant, 1e-12)))


def stride_scale_sigma(seg_walk: np.ndarray, true_m: np.ndarray, weinberg: np.ndarray, exclude: int) -> float:
    """Relative σ of the per-walk K of every walk but ``exclude`` over its scored segments (NaN: too few)."""
    ks = []
    for w in np.unique(seg_walk):
        m = seg_walk == w
        if w != exclude and weinberg[m].sum() > 0:
            ks.append(true_m[m].sum() / weinberg[m].sum())
    if len(ks) < MIN_WALKS:
        return math.nan
    return float(np.std(ks, ddof=1) / np.mean(ks))


def ekf_start_priors(
    rotation: Sequence[Mapping[str, Any]], seg_walk: Any, true_m: Any, weinberg: Any, exclude: int
) -> dict[str, float]:
    """The priors of walk ``exclude``'s fold (only those with enough data), as ``--set`` values."""
    out = {}
    b = heading_bias_sigma_rad(rotation, exclude)
    if math.isfinite(b):
        out["ekf.init_bias_sigma_rad"] = float(np.clip(b, *BIAS_SIGMA_RANGE_RAD))
    s = stride_scale_sigma(
        np.asarray(seg_walk), np.asarray(true_m, float), np.asarray(weinberg, float), exclude
    )
    if math.isfinite(s):
        out["ekf.init_scale_sigma"] = float(np.clip(s, *SCALE_SIGMA_RANGE))
    q = bias_rw_rad2_per_m(rotation, exclude)
    if math.isfinite(q):
        out["ekf.bias_rw_rad2_per_m"] = float(np.clip(q, *BIAS_RW_RANGE_RAD2_PER_M))
    return out
