"""Stride statistics of real walks: Weinberg sums over the segments between waypoints, and the
calibrations from them: Weinberg K over every walk (:func:`stride_k`, what ``stridefix site`` learns) and
leave one walk out (:func:`calibrate_lowo`, both realbench benchmarks).

- Segment = two consecutive waypoints k, k+1 of a walk; true distance = the straight line between them
  [m]; Weinberg sum W = Σ range^¼ over the steps with t_k < t_step ≤ t_{k+1}; n_steps = their count.
- K_i = Σ true / Σ W over the scored segments of every *other* walk (:func:`calibrate_lowo`); the
  fixed-stride baseline is the median true / n_steps over the other walks (:func:`stride_lowo`).
- Segments are excluded (with the reason) when shorter than ``min_segment_m``, of zero duration, not
  covered by IMU data, or when the walk failed; implausible implied speeds are flagged, not excluded.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from stridefix_analyzer.io.logread import Table

DEFAULT_MIN_SEGMENT_M = 3.0
#: Waypoints this far outside the IMU data [s] still count as covered (sensor start-up jitter).
IMU_COVER_TOLERANCE_S = 0.5
#: Segments implying a walk faster / slower than these [m/s] are flagged as suspect (not excluded):
#: too fast = waypoint times off; too slow = a stop, a detour or a turn-around between the waypoints,
#: where the straight line underestimates the distance walked.
SUSPECT_SPEED_MPS = 2.5
SUSPECT_SLOW_MPS = 0.5
WEINBERG_EXPONENT = 0.25


def build_segments(walks: Sequence[dict[str, Any]], min_segment_m: float = DEFAULT_MIN_SEGMENT_M) -> Table:
    """One row per pair of consecutive waypoints of every walk.

    Returns
    -------
    Table
        ``walk`` (index into ``walks``), ``k`` (first waypoint), ``t0_us``, ``t1_us``, ``true_m``,
        ``weinberg`` (Σ range^¼ [(m/s²)^¼]), ``n_steps``, ``fw_length_m`` (Σ firmware length_m),
        ``speed_mps`` (true / duration), ``bad_range`` (steps with a non-finite or negative range),
        ``suspect`` (implied speed above :data:`SUSPECT_SPEED_MPS` or below
        :data:`SUSPECT_SLOW_MPS`), ``excluded`` ('' when
        scored, else the reason).
    """
    rows = []
    for w, walk in enumerate(walks):
        if walk.get("error") or "waypoint_t_us" not in walk:
            n_wp = walk["import"]["waypoints"] if walk.get("import") else 0
            for k in range(max(n_wp - 1, 0)):
                rows.append((w, k, 0, 0, math.nan, math.nan, 0, math.nan, math.nan, 0, False, "walk failed"))
            continue
        t_wp, xy = walk["waypoint_t_us"], walk["waypoint_xy_m"]
        t_st = walk["step_t_us"]
        rng = walk["step_range_mps2"]
        bad = ~np.isfinite(rng) | (rng < 0)
        root = np.where(bad, 0.0, np.abs(rng)) ** WEINBERG_EXPONENT
        imu0, imu1 = walk["import"].get("imu_t_first_us"), walk["import"].get("imu_t_last_us")
        tol = IMU_COVER_TOLERANCE_S * 1e6
        for k in range(len(t_wp) - 1):
            t0, t1 = int(t_wp[k]), int(t_wp[k + 1])
            true_m = float(np.hypot(*(xy[k + 1] - xy[k])))
            # steps with t0 < t <= t1
            i0, i1 = np.searchsorted(t_st, [t0, t1], side="right")
            duration_s = (t1 - t0) / 1e6
            speed = true_m / duration_s if duration_s > 0 else math.inf
            if imu0 is None or t0 < imu0 - tol or t1 > imu1 + tol:
                reason = "not covered by IMU data"
            elif t1 <= t0:
                reason = "zero duration"
            elif true_m < min_segment_m:
                reason = f"shorter than {min_segment_m:g} m"
            else:
                reason = ""
            rows.append(
                (
                    w,
                    k,
                    t0,
                    t1,
                    true_m,
                    float(root[i0:i1].sum()),
                    int(i1 - i0),
                    float(walk["step_length_m"][i0:i1].sum()),
                    speed,
                    int(bad[i0:i1].sum()),
                    bool(speed > SUSPECT_SPEED_MPS or speed < SUSPECT_SLOW_MPS),
                    reason,
                )
            )
    names = [
        "walk",
        "k",
        "t0_us",
        "t1_us",
        "true_m",
        "weinberg",
        "n_steps",
        "fw_length_m",
        "speed_mps",
        "bad_range",
        "suspect",
        "excluded",
    ]
    cols: list[Sequence[Any]] = list(zip(*rows)) if rows else [[] for _ in names]
    dtypes = [
        np.int64,
        np.int64,
        np.int64,
        np.int64,
        float,
        float,
        np.int64,
        float,
        float,
        np.int64,
        bool,
        object,
    ]
    return Table({n: np.asarray(c, dtype=t) for n, c, t in zip(names, cols, dtypes)})


def calibrate_lowo(
    seg_walk: ArrayLike, true_m: ArrayLike, weinberg: ArrayLike, walks: ArrayLike | None = None
) -> np.ndarray:
    """Weinberg K per walk, leave one walk out.

    Parameters
    ----------
    seg_walk : (n,) int
        Walk of each (scored) segment.
    true_m : (n,) float
        True segment distances [m].
    weinberg : (n,) float
        Σ range^¼ of each segment's steps.
    walks : (m,) int, optional
        Walks to calibrate for (default: the distinct values of ``seg_walk``).

    Returns
    -------
    (m,) float
        K_i = Σ true / Σ weinberg over the segments of every walk except walk i [m/(m/s²)^¼];
        NaN when the other walks have no Weinberg sum.
    """
    seg_walk = np.asarray(seg_walk)
    true_m, weinberg = np.asarray(true_m, float), np.asarray(weinberg, float)
    walks = np.unique(seg_walk) if walks is None else np.asarray(walks)
    tot_true, tot_w = true_m.sum(), weinberg.sum()
    k = np.full(len(walks), math.nan)
    for j, w in enumerate(walks):
        mine = seg_walk == w
        den = tot_w - weinberg[mine].sum()
        if den > 0:
            k[j] = (tot_true - true_m[mine].sum()) / den
    return k


def stride_lowo(
    seg_walk: ArrayLike, true_m: ArrayLike, n_steps: ArrayLike, walks: ArrayLike | None = None
) -> np.ndarray:
    """Fixed stride per walk, leave one walk out: median of true / n_steps over the other walks'
    segments with at least one step [m]; NaN when there is none."""
    seg_walk, n_steps = np.asarray(seg_walk), np.asarray(n_steps)
    true_m = np.asarray(true_m, float)
    walks = np.unique(seg_walk) if walks is None else np.asarray(walks)
    has = n_steps > 0
    stride = np.where(has, true_m / np.maximum(n_steps, 1), math.nan)
    out = np.full(len(walks), math.nan)
    for j, w in enumerate(walks):
        s = stride[has & (seg_walk != w)]
        if len(s):
            out[j] = float(np.median(s))
    return out


def error_stats(err_pct: ArrayLike) -> dict[str, Any]:
    """n, mean, median, p75, p90, p95, max of absolute errors [%] (NaN-free input expected)."""
    e = np.abs(np.asarray(err_pct, float))
    e = e[np.isfinite(e)]
    if not len(e):
        return {"n": 0, **{k: math.nan for k in ("mean", "median", "p75", "p90", "p95", "max")}}
    p = np.percentile(e, [50, 75, 90, 95])
    return {
        "n": int(len(e)),
        "mean": float(e.mean()),
        "median": float(p[0]),
        "p75": float(p[1]),
        "p90": float(p[2]),
        "p95": float(p[3]),
        "max": float(e.max()),
    }


def stride_k(seg: Table, mask: np.ndarray) -> float:
    """Weinberg K of the segments in ``mask``: Σ true distance / Σ Weinberg sum (NaN when empty)."""
    w = seg["weinberg"][mask].sum()
    return float(seg["true_m"][mask].sum() / w) if w > 0 else math.nan


def spread(values: Iterable[float | None]) -> dict[str, Any]:
    """n, mean, std, min, max of the finite values (None and NaN left out): a fold statistic's spread."""
    v = np.asarray([x for x in values if x is not None], float)
    v = v[np.isfinite(v)]
    if not len(v):
        return {"n": 0, "mean": math.nan, "std": math.nan, "min": math.nan, "max": math.nan}
    return {
        "n": int(len(v)),
        "mean": float(v.mean()),
        "std": float(v.std()),
        "min": float(v.min()),
        "max": float(v.max()),
    }
