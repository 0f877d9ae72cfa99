"""Score the published POSE stream against TRUTH: the evaluation protocol of DESIGN.md.

Protocol (causal, nothing looks ahead): for each truth time t the estimate is the latest ``POSE``
with ``t_us ≤ t`` (of the same fusion scheme); the position error is the horizontal distance
between the two [m]. Truth samples before the scheme's first POSE are not scored but counted as
``unscored``. Statistics: n, mean, median, 75th/90th/95th percentile (numpy's default linear
interpolation), max and RMSE, plus the empirical CDF. Also floor hit rate, the IPIN score (the IPIN
competition's metric, :func:`ipin_score`, by Matlab's ``quantile`` as the organisers compute it:
:func:`matlab_quantile`), the ISO/IEC 18305 terms (:mod:`.iso18305`), step count against the truth,
distance walked along the truth, and the final error.

When a log holds POSE messages of several schemes (``pose_t.scheme``), each is scored on its own
and reported under its name; one of them is the *primary* scheme whose numbers are repeated at the
top level of the summary: the scheme the firmware published on ``POSE`` (:mod:`.primary`).

No plotting here: :mod:`stridefix_analyzer.plots` draws what this module computes.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import ArrayLike
from stridefix_common.exits import NothingValid

from stridefix_analyzer import schemes as registry
from stridefix_analyzer.io.logread import LogData, Table
from stridefix_analyzer.schemes import UnknownSchemeError, scheme_name
from stridefix_analyzer.scoring import iso18305
from stridefix_analyzer.scoring.floor_height import FloorHeights
from stridefix_analyzer.scoring.primary import FALLBACK, PrimaryError, choose_scheme

#: percentiles reported, in percent
PERCENTILES = (50, 75, 90, 95)
#: IPIN competition score: p75 of (2-D error + this × |floor error|) [m per floor]
IPIN_FLOOR_PENALTY_M = 15.0


class MetricsInputError(ValueError):
    """The logs lack what scoring needs (no TRUTH, no POSE, unknown scheme); the message says what."""


class NothingToScoreError(MetricsInputError, NothingValid):
    """The logs hold neither TRUTH nor POSE: nothing valid for scoring in them (``stridefix analyze``
    exits :data:`~stridefix_common.exits.EXIT_NOTHING_VALID`)."""


def scheme_code(name: str | int) -> int:
    """The id of a scheme given by name (``adaptive``, any case), number (``4``) or ``scheme_<id>``
    (the name :func:`~stridefix_analyzer.schemes.scheme_name` gives an id the LCM type does not
    know: such an id is returned as it is, and scoring then reports it absent from the POSE stream).
    Raises :class:`MetricsInputError` for anything else."""
    text = str(name).lower()
    text = text[len("scheme_") :] if text.startswith("scheme_") else text
    try:
        return registry.scheme_code(text)
    except UnknownSchemeError:
        try:
            return int(text)
        except ValueError:
            raise MetricsInputError(f"unknown scheme {name!r}; known: {list(registry.NAMES)}") from None


# --- the causal match ----------------------------------------------------------------------------


def match_causal(pose: Table, truth: Table) -> Table:
    """Pair every truth sample with the latest pose at or before its time.

    Parameters
    ----------
    pose : Table
        POSE rows of one scheme, sorted by ``t_us`` [µs] (equal times: the later row wins).
    truth : Table
        TRUTH rows, sorted by ``t_us`` [µs].

    Returns
    -------
    Table
        One row per truth sample, shape (n_truth,): ``t_us``, ``truth_x_m``, ``truth_y_m``,
        ``truth_floor``, ``scored`` (bool: a pose existed), ``pose_row`` (row in ``pose``, −1 when
        unscored), ``pose_t_us``, ``pose_x_m``, ``pose_y_m``, ``pose_floor``, ``pose_sigma_m``
        and ``error_m`` (horizontal distance [m], NaN when unscored).
    """
    t = truth["t_us"]
    row = np.searchsorted(pose["t_us"], t, side="right") - 1
    scored = row >= 0
    safe = np.where(scored, row, 0)

    def take(values: np.ndarray, fill):
        if len(values) == 0:
            return np.full(len(t), fill, dtype=np.asarray(fill).dtype)
        return np.where(scored, values[safe], fill)

    px, py = take(pose["x_m"], np.nan), take(pose["y_m"], np.nan)
    return Table(
        {
            "t_us": t,
            "truth_x_m": truth["x_m"],
            "truth_y_m": truth["y_m"],
            "truth_floor": truth["floor"],
            "scored": scored,
            "pose_row": np.where(scored, row, -1),
            "pose_t_us": take(pose["t_us"], np.int64(-1)),
            "pose_x_m": px,
            "pose_y_m": py,
            "pose_floor": take(pose["floor"], np.int64(-1)),
            "pose_sigma_m": take(pose["sigma_m"], np.nan),
            "error_m": np.hypot(px - truth["x_m"], py - truth["y_m"]),
            "heading_error_rad": wrap_pi(take(pose["heading_rad"], np.nan) - truth["heading_rad"]),
        }
    )


def wrap_pi(angle_rad: ArrayLike) -> np.ndarray:
    """Angles wrapped to (−π, π] [rad]; NaN stays NaN."""
    a = np.asarray(angle_rad, dtype=np.float64)
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def heading_stats(heading_error_rad: np.ndarray) -> dict:
    """RMS and mean absolute heading error [deg] over the finite samples, and their count."""
    e = np.degrees(np.asarray(heading_error_rad, dtype=np.float64))
    e = e[np.isfinite(e)]
    if e.size == 0:
        return {"n": 0, "rms_deg": float("nan"), "mean_abs_deg": float("nan")}
    return {
        "n": int(e.size),
        "rms_deg": float(np.sqrt(np.mean(e**2))),
        "mean_abs_deg": float(np.mean(np.abs(e))),
    }


# --- statistics ----------------------------------------------------------------------------------


def error_stats(error_m: np.ndarray) -> dict:
    """Summary statistics of position errors.

    Parameters
    ----------
    error_m : ndarray, shape (n,)
        Errors [m] of scored samples; non-finite values are left out and counted.

    Returns
    -------
    dict
        ``n``, ``mean``, ``median``, ``p75``, ``p90``, ``p95``, ``max``, ``rmse`` [m] (NaN when
        n = 0; percentiles by ``np.percentile``'s linear method) and ``nonfinite`` (count).
    """
    error_m = np.asarray(error_m, dtype=np.float64)
    finite = error_m[np.isfinite(error_m)]
    stats: dict[str, float] = {"n": int(finite.size), "nonfinite": int(error_m.size - finite.size)}
    if finite.size == 0:
        stats.update(dict.fromkeys(["mean", "median", "p75", "p90", "p95", "max", "rmse"], float("nan")))
        return stats
    p50, p75, p90, p95 = np.percentile(finite, PERCENTILES)
    stats.update(
        mean=float(finite.mean()),
        median=float(p50),
        p75=float(p75),
        p90=float(p90),
        p95=float(p95),
        max=float(finite.max()),
        rmse=float(np.sqrt(np.mean(finite**2))),
    )
    return stats


def matlab_quantile(values: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Quantiles as Matlab's ``quantile`` defines them (the IPIN organisers' scorer uses it).

    The i-th of the n sorted values sits at probability (i − 0.5)/n; linear in between; below 0.5/n
    the smallest value, above (n − 0.5)/n the largest. That is numpy's ``method="hazen"``
    (Hyndman & Fan type 5); numpy's default (``"linear"``, type 7) puts the i-th at (i − 1)/(n − 1).

    Parameters
    ----------
    values : array_like, shape (n,)
        Finite samples (n ≥ 1), any unit.
    q : float or array_like, shape (k,)
        Probabilities in [0, 1].

    Returns
    -------
    ndarray, shape () or (k,)
        The quantiles, in the unit of ``values``.
    """
    probability = np.asarray(q, dtype=np.float64)
    return np.asarray(np.quantile(np.asarray(values, dtype=np.float64), probability, method="hazen"))


def ipin_score(error_m: ArrayLike, floor_error: ArrayLike) -> float:
    """The IPIN competition score [m]: the 75th percentile by :func:`matlab_quantile` (as the
    organisers compute it) of 2-D error + :data:`IPIN_FLOOR_PENALTY_M` × |floor error|, over the
    samples where that sum is finite (NaN when there is none).

    Parameters
    ----------
    error_m : array_like, shape (n,)
        Horizontal position errors [m].
    floor_error : array_like, shape (n,)
        Floor errors at the same samples [floors]; the sign does not matter.
    """
    e = np.asarray(error_m, float) + IPIN_FLOOR_PENALTY_M * np.abs(np.asarray(floor_error, float))
    e = e[np.isfinite(e)]
    return float(matlab_quantile(e, 0.75)) if len(e) else float("nan")


def error_cdf(error_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Empirical CDF of the finite errors.

    Returns
    -------
    error_sorted_m : ndarray, shape (n,)
        Errors in ascending order [m].
    fraction : ndarray, shape (n,)
        Fraction of samples with error ≤ the corresponding value, (i + 1) / n.
    """
    e = np.sort(np.asarray(error_m, dtype=np.float64)[np.isfinite(error_m)])
    return e, np.arange(1, e.size + 1) / max(e.size, 1)


def distance_walked_m(truth: Table) -> float:
    """Horizontal path length along the time-sorted truth positions [m]."""
    if len(truth) < 2:
        return 0.0
    return float(np.sum(np.hypot(np.diff(truth["x_m"]), np.diff(truth["y_m"]))))


def step_metrics(pose: Table, truth: Table, n_step_messages: int) -> dict:
    """Detected steps against the truth's step count.

    ``detected`` is the last POSE's ``step_count`` (or the number of STEP messages when there is no
    POSE); ``truth`` is the last TRUTH ``step_count`` that is ≥ 0 (None when the truth has none).
    ``error`` = detected − truth [steps]; ``error_pct`` = 100·error/truth [%].
    """
    detected = int(pose["step_count"][-1]) if len(pose) else int(n_step_messages)
    known = truth["step_count"][truth["step_count"] >= 0] if len(truth) else np.array([])
    out: dict[str, float | None] = {
        "detected": detected,
        "step_messages": int(n_step_messages),
        "truth": None,
        "error": None,
        "error_pct": None,
    }
    if known.size:
        t = int(known[-1])
        out.update(truth=t, error=detected - t, error_pct=(100.0 * (detected - t) / t) if t > 0 else None)
    return out


# --- one scheme, and the whole log ---------------------------------------------------------------


@dataclasses.dataclass
class SchemeScore:
    """Scores of one fusion scheme.

    Attributes
    ----------
    code, name : int, str
        pose_t.scheme code and its name.
    summary : dict
        JSON-ready numbers: ``n_pose``, ``position_error_m`` (see :func:`error_stats`),
        ``unscored``, ``floor_hit_rate``, ``ipin_score`` [m] (:func:`ipin_score`), ``iso18305``
        (:func:`stridefix_analyzer.scoring.iso18305.terms`),
        ``within_1sigma_rate``, ``steps``, ``final_error_m``, ``final_error_pct_of_distance``.
    match : Table
        Per-truth-sample series from :func:`match_causal`, shape (n_truth,).
    pose : Table
        This scheme's POSE rows (for trajectory plots).
    """

    code: int
    name: str
    summary: dict
    match: Table
    pose: Table


def scored_errors(match: Table) -> tuple[np.ndarray, np.ndarray]:
    """(2-D error [m], |floor error| [floors]) at the scored rows of a :func:`match_causal` table
    (a :attr:`SchemeScore.match`), shape (n_scored,) each: what :func:`ipin_score` takes, and what a
    benchmark pools over walks."""
    sc = match["scored"]
    floor_error = np.abs(match["pose_floor"][sc] - match["truth_floor"][sc]).astype(np.int64)
    return match["error_m"][sc].astype(np.float64), floor_error


def score_scheme(
    pose: Table,
    truth: Table,
    n_step_messages: int,
    distance_m: float,
    code: int,
    heights: FloorHeights | None = None,
) -> SchemeScore:
    """Score one scheme's POSE rows (sorted by time) against the TRUTH rows (sorted by time);
    ``heights`` gives the ISO/IEC 18305 terms their vertical part (:mod:`.iso18305`)."""
    m = match_causal(pose, truth)
    scored = m["scored"]
    err, floor_err = scored_errors(m)
    floor_hit = float(np.mean(floor_err == 0)) if scored.any() else float("nan")
    sig = m["pose_sigma_m"][scored]
    ok = np.isfinite(err) & np.isfinite(sig) & (sig > 0)
    within = float(np.mean(err[ok] <= sig[ok])) if ok.any() else float("nan")
    final = float(err[-1]) if err.size else float("nan")
    summary = {
        "n_pose": len(pose),
        "position_error_m": error_stats(err),
        "unscored": int(np.count_nonzero(~scored)),
        "floor_hit_rate": floor_hit,
        "ipin_score": ipin_score(err, floor_err),
        "iso18305": iso18305.terms(m, heights),
        "within_1sigma_rate": within,
        "heading_error": heading_stats(m["heading_error_rad"][scored]),
        "steps": step_metrics(pose, truth, n_step_messages),
        "final_error_m": final,
        "final_error_pct_of_distance": 100.0 * final / distance_m if distance_m > 0 else None,
    }
    return SchemeScore(code=int(code), name=scheme_name(code), summary=summary, match=m, pose=pose)


def choose_primary(data: LogData, requested: int | None = None) -> tuple[int, str]:
    """(the primary scheme, how it was chosen): :func:`stridefix_analyzer.scoring.primary.choose_scheme`
    on the log's POSE table and the scheme its POSE channel carried. Raises :class:`MetricsInputError`."""
    pose = data.table("POSE")
    if pose is None or not len(pose):
        raise MetricsInputError("no POSE messages: no primary scheme")
    try:
        return choose_scheme(pose["scheme"], requested, data.pose_channel_scheme)
    except PrimaryError as exc:
        raise MetricsInputError(str(exc)) from None


@dataclasses.dataclass
class Metrics:
    """All scores of one analysis.

    Attributes
    ----------
    primary : int
        pose_t.scheme code of the primary scheme.
    schemes : dict of int to SchemeScore
        Every scheme seen in POSE, by code.
    truth : Table
        TRUTH rows sorted by time.
    distance_walked_m : float
        Horizontal path length of the truth [m].
    heights : FloorHeights or None
        Floor index → height used for the vertical terms (and TUM z); None when not given.
    """

    primary: int
    schemes: dict
    truth: Table
    distance_walked_m: float
    heights: FloorHeights | None = None
    primary_from: str = FALLBACK

    def summary(self) -> dict:
        """JSON-ready dict: the primary scheme's numbers at the top level plus ``per_scheme``."""
        top = self.schemes[self.primary].summary
        return {
            "primary_scheme": scheme_name(self.primary),
            "primary_from": self.primary_from,
            "position_error_m": top["position_error_m"],
            "unscored": top["unscored"],
            "n_truth": len(self.truth),
            "floor_hit_rate": top["floor_hit_rate"],
            "ipin_score": top["ipin_score"],
            "iso18305": top["iso18305"],
            "floor_heights": self.heights.source if self.heights is not None else None,
            "floors_in_truth": sorted({int(f) for f in self.truth["floor"]}),
            "within_1sigma_rate": top["within_1sigma_rate"],
            "heading_error": top["heading_error"],
            "steps": top["steps"],
            "distance_walked_m": self.distance_walked_m,
            "final_error_m": top["final_error_m"],
            "final_error_pct_of_distance": top["final_error_pct_of_distance"],
            "per_scheme": {s.name: s.summary for s in self.schemes.values()},
        }

    def series(self) -> dict[str, np.ndarray]:
        """Per-sample arrays for the report (saved as analysis.npz).

        Keys: ``truth_t_us``, ``truth_x_m``, ``truth_y_m``, ``truth_floor`` (n_truth,);
        the primary scheme's ``scored``, ``match_x_m``, ``match_y_m``, ``match_floor``,
        ``error_m`` (n_truth,); ``scheme_codes`` (n_schemes,); ``primary_scheme`` (scalar); and per
        scheme code c: ``s<c>_error_m``, ``s<c>_scored`` (n_truth,), ``s<c>_pose_t_us``,
        ``s<c>_pose_x_m``, ``s<c>_pose_y_m``, ``s<c>_pose_floor`` (n_pose of that scheme,).
        Unscored errors are NaN.
        """
        p = self.schemes[self.primary].match
        out = {
            "truth_t_us": self.truth["t_us"],
            "truth_x_m": self.truth["x_m"],
            "truth_y_m": self.truth["y_m"],
            "truth_floor": self.truth["floor"],
            "scored": p["scored"],
            "match_x_m": p["pose_x_m"],
            "match_y_m": p["pose_y_m"],
            "match_floor": p["pose_floor"],
            "error_m": p["error_m"],
            "scheme_codes": np.array(sorted(self.schemes), dtype=np.int64),
            "primary_scheme": np.int64(self.primary),
        }
        for code, s in self.schemes.items():
            out[f"s{code}_error_m"] = s.match["error_m"]
            out[f"s{code}_scored"] = s.match["scored"]
            for col in ("t_us", "x_m", "y_m", "floor"):
                out[f"s{code}_pose_{col}"] = s.pose[col]
        return out


TRUTH_SOURCES = {"simulation": 1, "waypoint": 2}


def run_metrics(
    data: LogData,
    scheme: int | None = None,
    truth_source: str | None = None,
    heights: FloorHeights | None = None,
) -> Metrics:
    """Score every POSE scheme in ``data`` against its TRUTH.

    Parameters
    ----------
    data : LogData
        Logs read by :func:`stridefix_analyzer.logread.read_logs`.
    scheme : int, optional
        pose_t.scheme code to make primary (default: see :func:`choose_primary`).
    truth_source : {"simulation", "waypoint"}, optional
        Score only TRUTH rows of this source (truth_t.SOURCE_*): e.g. the reference points of a
        walk ("waypoint") instead of the simulator's 10 Hz truth. Default: every TRUTH row.
    heights : FloorHeights, optional
        Floor index → height, for the vertical ISO/IEC 18305 terms (none without).

    Raises
    ------
    MetricsInputError
        No TRUTH or no POSE messages (both listed when both are missing: :class:`NothingToScoreError`),
        or ``scheme`` absent.
    """
    truth, pose = data.table("TRUTH"), data.table("POSE")
    missing = [ch for ch, t in (("TRUTH", truth), ("POSE", pose)) if t is None or not len(t)]
    if truth is None or pose is None or missing:
        error = NothingToScoreError if len(missing) == 2 else MetricsInputError
        raise error(
            f"no {' and no '.join(missing)} messages in "
            f"{', '.join(i['path'] for i in data.inputs) or 'the input'}"
        )
    if truth_source is not None:
        if truth_source not in TRUTH_SOURCES:
            raise MetricsInputError(f"unknown truth source {truth_source!r}; known: {list(TRUTH_SOURCES)}")
        truth = truth.rows(truth["source"] == TRUTH_SOURCES[truth_source])
        if not len(truth):
            raise MetricsInputError(f"no TRUTH messages of source {truth_source!r}")
    steps = data.table("STEP")
    n_steps = len(steps) if steps is not None else 0
    distance = distance_walked_m(truth)
    chosen, chosen_from = choose_primary(data, scheme)
    schemes = {}
    for code in np.unique(pose["scheme"]):
        rows = pose.rows(pose["scheme"] == code)  # stays sorted by time
        schemes[int(code)] = score_scheme(rows, truth, n_steps, distance, int(code), heights)
    return Metrics(chosen, schemes, truth, distance, heights, chosen_from)
