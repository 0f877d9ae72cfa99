"""A walk without ground truth: what the firmware's own log says about it.

Every field recording lacks TRUTH, so none of :mod:`.metrics`'s errors exist for it; these figures
need none. :func:`run_walk` folds a log's POSE, STEP, FIX, BARO and HEALTH into :class:`Walk`:

- per scheme: poses, duration [s], track length [m] (horizontal path of its poses, fix jumps
  included), floors visited, the σ the estimator claims (``pose_t.sigma_m``: median, p95, max,
  final [m]) and the **consistency of its fixes' innovations** (below);
- for the walk: steps (STEP messages, the stride lengths' sum [m], cadence [steps/min] = 60 / median
  step period of walking steps), time and steps per activity (``step_t.ACTIVITY_*``), the floors the
  primary pose visited, the barometric height [m] relative to the first second (international
  barometric formula) and the HEALTH counters that grew over the walk.

Innovation consistency. Each FIX record carries the innovation ν (fix − predicted, 2-D [m]) and the
test ratio ν²/(g²·S) against the innovation variance S the scheme claims (g = ``fusion.gate_sigma``
from CONFIG). The normalised innovation squared NIS = test ratio · g² is ν'S⁻¹ν: for a scheme whose
claimed covariance (its state's plus the fix's accuracy) is honest it is χ² with 2 degrees of
freedom, mean 2, and 95 % of fixes fall within :data:`CHI2_2DOF_95` = 5.99 (Bar-Shalom, Li &
Kirubarajan 2001, §5.4). Both are computed over every *judged* fix (accepted, rejected by the gate,
recovered from rejections, or refused between floors: :data:`JUDGED`), not only the accepted ones:
the gate accepts NIS ≤ g² only, so the accepted fixes' NIS is cut off by construction and would
look consistent whatever the truth. No truth enters: ν and S are both observable, which makes it a
fair check of the claimed σ on a field walk. Mean NIS ≫ 2 says the scheme (or the fix accuracy it is
given) claims too little; ≪ 2 too much. Fixes of one radio map are correlated, so it is a check, not
a significance test. Fixes a scheme ignores or that initialise it carry no NIS.

No plotting here: :mod:`.walk_plots` draws :meth:`Walk.series`, :mod:`.walk_report` the HTML.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from stridefix import fix_t, step_t

from stridefix_analyzer.io.logread import LogData, Table
from stridefix_analyzer.schemes import scheme_name
from stridefix_analyzer.scoring.fixsources import method_name

#: the χ² 95 % quantile with 2 degrees of freedom, −2·ln(0.05) (scipy.stats.chi2.ppf(0.95, 2))
CHI2_2DOF_95 = float(-2.0 * np.log(0.05))
#: FIX reasons whose record compared the fix with the scheme's prediction (the NIS exists)
JUDGED = (fix_t.REASON_ACCEPTED, fix_t.REASON_GATE, fix_t.REASON_RECOVERY, fix_t.REASON_FLOOR_MISMATCH)
#: the firmware's default fusion.gate_sigma, for a log without CONFIG
DEFAULT_GATE_SIGMA = 3.0
#: step_t.ACTIVITY_* id → name
ACTIVITY_NAMES: dict[int, str] = {
    int(v): k[len("ACTIVITY_") :].lower() for k, v in vars(step_t).items() if k.startswith("ACTIVITY_")
}
#: barometric height, the international barometric formula: h = H·(1 − (p/p0)^E) [m]
_BARO_H_M, _BARO_E = 44330.0, 1.0 / 5.255


def _stats(values: np.ndarray) -> dict[str, Any]:
    v = np.asarray(values, np.float64)
    v = v[np.isfinite(v)]
    if not v.size:
        return {"n": 0, "median": None, "p95": None, "max": None, "final": None}
    return {
        "n": int(v.size),
        "median": float(np.median(v)),
        "p95": float(np.percentile(v, 95)),
        "max": float(v.max()),
        "final": float(v[-1]),
    }


def nis_of(fix: Table, gate_sigma: float) -> np.ndarray:
    """NIS = test ratio · gate² per FIX record, NaN where the record judged nothing (module docstring)."""
    judged = np.isin(fix["reason"], JUDGED) & np.isfinite(fix["test_ratio"])
    return np.where(judged, fix["test_ratio"] * gate_sigma**2, np.nan)


def consistency(nis: np.ndarray, accepted: np.ndarray) -> dict[str, Any]:
    """NIS figures of a set of FIX records: ``judged`` (records with a NIS), ``nis_mean`` (expected 2),
    ``within_chi2_95_rate`` (expected 0.95), ``accepted_nis_mean`` (cut off at the gate)."""
    ok = np.isfinite(nis)
    acc = ok & np.asarray(accepted, bool)
    return {
        "judged": int(ok.sum()),
        "nis_mean": float(np.mean(nis[ok])) if ok.any() else None,
        "within_chi2_95_rate": float(np.mean(nis[ok] <= CHI2_2DOF_95)) if ok.any() else None,
        "accepted_nis_mean": float(np.mean(nis[acc])) if acc.any() else None,
    }


def scheme_walk(pose: Table, fix: Table | None, nis: np.ndarray | None) -> dict[str, Any]:
    """One scheme's truth-less figures (module docstring) from its POSE rows (sorted by time) and FIX
    rows with their NIS."""
    t = pose["t_us"]
    out: dict[str, Any] = {
        "n_pose": len(pose),
        "duration_s": float((t[-1] - t[0]) / 1e6) if len(t) else 0.0,
        "track_length_m": float(np.sum(np.hypot(np.diff(pose["x_m"]), np.diff(pose["y_m"])))),
        "floors_visited": sorted({int(f) for f in pose["floor"]}),
        "sigma_m": _stats(pose["sigma_m"]),
        "fixes": {"offered": 0, "accepted": 0, **consistency(np.array([]), np.array([], bool))},
        "fixes_by_method": {},
    }
    if fix is not None and nis is not None and len(fix):
        accepted = fix["accepted"].astype(bool)
        out["fixes"] = {"offered": len(fix), "accepted": int(accepted.sum()), **consistency(nis, accepted)}
        for m in np.unique(fix["method"]):
            sel = fix["method"] == m
            out["fixes_by_method"][method_name(int(m))] = {
                "offered": int(sel.sum()),
                "accepted": int(accepted[sel].sum()),
                **consistency(nis[sel], accepted[sel]),
            }
    return out


def step_walk(steps: Table | None, primary_pose: Table) -> dict[str, Any]:
    """Steps, stride sum [m], cadence [steps/min] and time/steps per activity."""
    if steps is None or not len(steps):
        n = int(primary_pose["step_count"][-1]) if len(primary_pose) else 0
        return {"count": n, "step_messages": 0, "walked_m": None, "cadence_spm": None, "activity": {}}
    period = steps["period_s"].astype(np.float64)
    walking = (steps["activity"] == step_t.ACTIVITY_WALKING) & np.isfinite(period) & (period > 0)
    activity = {}
    for a in np.unique(steps["activity"]):
        sel = steps["activity"] == a
        p = period[sel]
        activity[ACTIVITY_NAMES.get(int(a), f"activity_{int(a)}")] = {
            "steps": int(sel.sum()),
            "seconds": float(np.sum(p[np.isfinite(p) & (p > 0)])),
        }
    return {
        "count": int(steps["index"].max()),
        "step_messages": len(steps),
        "walked_m": float(np.sum(steps["length_m"])),
        "cadence_spm": float(60.0 / np.median(period[walking])) if walking.any() else None,
        "activity": activity,
    }


def baro_height_m(baro: Table | None) -> tuple[np.ndarray, np.ndarray]:
    """(t_us, height [m]) of every BARO sample relative to the median pressure of the first second."""
    if baro is None or not len(baro):
        return np.array([], np.int64), np.array([])
    p = baro["pressure_pa"].astype(np.float64)
    ok = np.isfinite(p) & (p > 0)
    t, p = baro["t_us"][ok], p[ok]
    if not len(p):
        return t, p
    p0 = float(np.median(p[t <= t[0] + 1_000_000]))
    return t, _BARO_H_M * (1.0 - (p / p0) ** _BARO_E)


#: HEALTH columns that are times, not counters
_HEALTH_TIMES = ("t_us", "host_t_us")


def health_growth(health: Table | None) -> dict[str, Any]:
    """HEALTH over the walk: reports, their span [s] and each integer counter's growth (last −
    first report) where it grew."""
    if health is None or not len(health):
        return {"reports": 0, "span_s": None, "grew": {}}
    grew = {}
    for name in health.names:
        col = health[name]
        if name in _HEALTH_TIMES or col.dtype.kind not in "iu":
            continue
        if int(col[-1]) > int(col[0]):
            grew[name] = int(col[-1]) - int(col[0])
    t = health["t_us"]
    return {"reports": len(health), "span_s": float((t[-1] - t[0]) / 1e6), "grew": grew}


@dataclasses.dataclass
class Walk:
    """The truth-less figures of one log (module docstring); ``summary`` is metrics.json's ``walk``."""

    primary: int
    primary_from: str
    summary: dict[str, Any]
    poses: dict[int, Table]
    fix: Table | None
    nis: np.ndarray | None
    steps: Table | None
    baro: tuple[np.ndarray, np.ndarray]
    health: Table | None

    def series(self) -> dict[str, np.ndarray]:
        """Arrays for the report (into analysis.npz, beside a scored analysis's): ``scheme_codes``,
        ``primary_scheme``, per scheme code c ``s<c>_pose_{t_us,x_m,y_m,floor,sigma_m}``; ``walk_step_*``
        (t_us, index, activity, length_m, floor), ``walk_fix_*`` (t_us, scheme, method, accepted,
        reason, innovation_x_m, innovation_y_m, innovation_var_m2, nis), ``walk_baro_t_us``,
        ``walk_baro_height_m``, ``walk_health_t_us`` and ``walk_health_<counter>`` for the counters
        that grew."""
        out: dict[str, np.ndarray] = {
            "scheme_codes": np.array(sorted(self.poses), np.int64),
            "primary_scheme": np.array(self.primary, np.int64),
        }
        for c, pose in self.poses.items():
            for col in ("t_us", "x_m", "y_m", "floor", "sigma_m"):
                out[f"s{c}_pose_{col}"] = pose[col]
        if self.steps is not None:
            for col in ("t_us", "index", "activity", "length_m", "floor"):
                out[f"walk_step_{col}"] = self.steps[col]
        if self.fix is not None and self.nis is not None:
            for col in ("t_us", "scheme", "method", "accepted", "reason", "innovation_x_m", "innovation_y_m"):
                out[f"walk_fix_{col}"] = self.fix[col]
            out["walk_fix_innovation_var_m2"] = self.fix["innovation_var_m2"]
            out["walk_fix_nis"] = self.nis
        out["walk_baro_t_us"], out["walk_baro_height_m"] = self.baro
        if self.health is not None and len(self.health):
            out["walk_health_t_us"] = self.health["t_us"]
            for name in self.summary["health"]["grew"]:
                out[f"walk_health_{name}"] = self.health[name]
        return out


def gate_sigma(config: dict[str, str]) -> tuple[float, str]:
    """(fusion.gate_sigma, where it came from): the log's CONFIG, else the firmware default."""
    try:
        return float(config["fusion.gate_sigma"]), "CONFIG fusion.gate_sigma"
    except (KeyError, ValueError):
        return DEFAULT_GATE_SIGMA, "firmware default (no fusion.gate_sigma in CONFIG)"


def run_walk(data: LogData, primary: int, primary_from: str) -> Walk:
    """The truth-less figures of ``data`` with ``primary`` the primary scheme, chosen as
    ``primary_from`` says (:mod:`.primary`); the POSE table must hold poses (the caller checked)."""
    pose = data.table("POSE")
    assert pose is not None and len(pose)
    poses = {int(c): pose.rows(pose["scheme"] == c) for c in np.unique(pose["scheme"])}
    fix = data.table("FIX")
    gate, gate_from = gate_sigma(data.config)
    nis = nis_of(fix, gate) if fix is not None else None
    per_scheme = {}
    for c, rows in poses.items():
        if fix is None or nis is None:
            per_scheme[scheme_name(c)] = scheme_walk(rows, None, None)
        else:
            sel = fix["scheme"] == c
            per_scheme[scheme_name(c)] = scheme_walk(rows, fix.rows(sel), nis[sel])
    top = poses[primary]
    floors = top["floor"]
    baro = baro_height_m(data.table("BARO"))
    h = baro[1]
    health = data.table("HEALTH")
    t0, t1 = int(pose["t_us"][0]), int(pose["t_us"][-1])
    summary = {
        "duration_s": (t1 - t0) / 1e6,
        "steps": step_walk(data.table("STEP"), top),
        "floors_visited": sorted({int(f) for f in floors}),
        "floor_changes": int(np.count_nonzero(np.diff(floors))),
        "barometric_height_m": {
            "n": len(h),
            "min": float(h.min()) if len(h) else None,
            "max": float(h.max()) if len(h) else None,
            "final": float(h[-1]) if len(h) else None,
        },
        "health": health_growth(health),
        "consistency": {
            "gate_sigma": gate,
            "gate_sigma_from": gate_from,
            "chi2_dof": 2,
            "chi2_95": CHI2_2DOF_95,
            "expected_nis_mean": 2.0,
        },
        "per_scheme": per_scheme,
    }
    return Walk(primary, primary_from, summary, poses, fix, nis, data.table("STEP"), baro, health)
