"""What ``bench reliability`` (reliability.py) asks of a fault beyond the common checks, measured on
the case's outputs next to the clean run's (both runs are the same walk, same seed; the faults draw
from their own random stream, so every sample the fault spares is the clean run's, bit for bit).

* ``board_time_stuck``: BOARD_TIME repeats one value for a while as the samples go on. After the
  window, each IMU sample's output time is the clean run's for the same sample (matched by its six
  values, which the fault does not touch) within :data:`TIME_TOL_MS`, for at least
  :data:`MATCHED_MIN` of the clean run's samples after it; and the mean error of ``pdr_only`` and of
  the primary scheme after the window is like the clean run's after it (within ERR_FACTOR x clean +
  ERR_MARGIN_M, the common rule). The common checks apply too.
* ``imu_failed``: the IMU reads full scale from a time on. The common checks do not apply (the walk
  goes on unseen: no steps, a growing error); instead stridefixd keeps running and logging (its raw
  samples and HEALTH reach within :data:`END_SLACK_S` of the walk's end), its POSE messages (every
  POSE channel) stay within :data:`POSE_VOLUME_MAX` x the clean run's, no STEP comes later than
  :data:`STEP_GRACE_S` into the failure, and the Wi-Fi fixes go on: the Wi-Fi fixes FIX audits during
  the failure are at least :data:`WIFI_MIN` of the clean run's in the same window (without a site
  there are none: not applicable).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import stridefix
from stridefix_analyzer import schemes
from stridefix_analyzer.io.logread import read_logs

TIME_TOL_MS = 10.0  # output times after a stuck BOARD_TIME within this of the clean run's
MATCHED_MIN = 0.9  # ... for at least this fraction of the clean run's IMU samples after it
POSE_VOLUME_MAX = 1.2  # POSE messages with a failed IMU at most this x the clean run's
STEP_GRACE_S = 2.0  # a step under way when the IMU fails may still end
WIFI_MIN = 0.9  # Wi-Fi fixes during the failure at least this x the clean run's
END_SLACK_S = 5.0  # the log reaches this close to the walk's end
LOG = "stridefixd.lcmlog"
SERIES = "analysis.npz"  # stridefix analyze's per-truth-sample series

#: fault kind → whether its checks replace the common ones
KINDS = {"board_time_stuck": False, "imu_failed": True}


def window_s(row: dict[str, Any]) -> tuple[float, float]:
    """The fault's [start, end) in walk time [s] from the case's scenario keys."""
    f = row["overrides"]["faults"]
    at, length = (("board_time_stuck_at_s", "board_time_stuck_s"), ("imu_failed_at_s", "imu_failed_s"))[
        row["fault"] == "imu_failed"
    ]
    start = float(f[at][0])
    return start, start + float(f[length])


def _imu_times(log: Path) -> dict[bytes, int]:
    """IMU sample (its six values' bytes) → output time [µs], for the samples whose values are unique."""
    imu = read_logs([log], decode=("IMU",)).table("IMU")
    if imu is None:
        return {}
    cols = [f"{q}_{a}_{u}" for q, u in (("accel", "mps2"), ("gyro", "radps")) for a in "xyz"]
    values = np.ascontiguousarray(np.stack([np.asarray(imu[c], dtype=np.float64) for c in cols], axis=1))
    keys = [v.tobytes() for v in values]
    seen: dict[bytes, int] = {}
    twice = set()
    for k, t in zip(keys, np.asarray(imu["t_us"], dtype=np.int64).tolist()):
        if k in seen:
            twice.add(k)
        seen[k] = t
    return {k: t for k, t in seen.items() if k not in twice}


def _mean_error_after(case_dir: Path, scheme: str, after_us: int) -> float | None:
    """Mean 2-D error [m] of ``scheme`` over the scored truth samples at or after ``after_us``."""
    with np.load(case_dir / SERIES) as z:
        key = f"s{schemes.scheme_code(scheme)}_error_m"
        if key not in z:
            return None
        err = z[key][z["truth_t_us"] >= after_us]
    err = err[np.isfinite(err)]
    return float(err.mean()) if len(err) else None


def _stuck(row: dict[str, Any], clean: dict[str, Any]) -> dict[str, Any]:
    _, end_s = window_s(row)
    after_us = row["start_us"] + round(end_s * 1e6)
    ref = {k: t for k, t in _imu_times(Path(clean["dir"]) / LOG).items() if t >= after_us}
    got = _imu_times(Path(row["dir"]) / LOG)
    dt_ms = [abs(got[k] - t) / 1000 for k, t in ref.items() if k in got]
    errors = {}
    for scheme in (schemes.PDR_ONLY, clean["primary_scheme"]):
        errors[scheme] = {
            "case": _mean_error_after(Path(row["dir"]), scheme, after_us),
            "clean": _mean_error_after(Path(clean["dir"]), scheme, after_us),
        }
    return {
        "after_s": end_s,
        "imu_after_clean": len(ref),
        "imu_after_matched": len(dt_ms),
        "time_offset_after_max_ms": max(dt_ms) if dt_ms else None,
        "mean_error_after_m": errors,
    }


def _failed(row: dict[str, Any], clean: dict[str, Any]) -> dict[str, Any]:
    start_s, end_s = window_s(row)
    t0 = row["start_us"] + round(start_s * 1e6)
    t1 = min(row["start_us"] + round(end_s * 1e6), row["end_us"])
    out: dict[str, Any] = {"failed_s": [start_s, min(end_s, (row["end_us"] - row["start_us"]) / 1e6)]}
    for who, r in (("case", row), ("clean", clean)):
        data = read_logs([Path(r["dir"]) / LOG], decode=("IMU", "HEALTH", "STEP", "FIX"))
        last = [int(np.max(t["t_us"])) for t in (data.table("IMU"), data.table("HEALTH")) if t is not None]
        step, fix = data.table("STEP"), data.table("FIX")
        step_t = np.asarray(step["t_us"]) if step is not None else np.zeros(0)
        wifi_t = (
            np.unique(np.asarray(fix["t_us"])[np.asarray(fix["method"]) == stridefix.fix_t.METHOD_WIFI])
            if fix is not None
            else np.zeros(0)
        )
        in_fail = (wifi_t >= t0) & (wifi_t < t1)
        accepted = 0
        if fix is not None:
            sel = (np.asarray(fix["method"]) == stridefix.fix_t.METHOD_WIFI) & np.asarray(fix["accepted"])
            t_acc = np.asarray(fix["t_us"])[sel]
            accepted = len(np.unique(t_acc[(t_acc >= t0) & (t_acc < t1)]))
        out[who] = {
            "pose_messages": sum(n for ch, n in data.messages.items() if ch.startswith("POSE")),
            "log_bytes": sum(int(i["bytes"]) for i in data.inputs),
            "last_output_before_end_s": (row["end_us"] - max(last)) / 1e6 if last else None,
            "steps_after_grace": int(np.sum((step_t >= t0 + round(STEP_GRACE_S * 1e6)) & (step_t < t1))),
            "wifi_fixes_in_failure": int(in_fail.sum()),
            "wifi_fixes_accepted_in_failure": accepted,
        }
    return out


def measure(row: dict[str, Any], clean: dict[str, Any]) -> dict[str, Any] | None:
    """The fault-specific measures of one case (None for a kind without any)."""
    if row["fault"] == "board_time_stuck":
        return _stuck(row, clean)
    if row["fault"] == "imu_failed":
        return _failed(row, clean)
    return None


def checks(row: dict[str, Any], err_factor: float, err_margin_m: float) -> dict[str, bool | None]:
    """The fault-specific checks of one case from its :func:`measure` (None: not applicable)."""
    m = row.get("measures")
    if m is None:
        return {}
    if row["fault"] == "board_time_stuck":
        off = m["time_offset_after_max_ms"]
        errs = m["mean_error_after_m"].values()
        return {
            "times_after": off is not None
            and off <= TIME_TOL_MS
            and m["imu_after_matched"] >= MATCHED_MIN * m["imu_after_clean"],
            "error_after": all(
                e["case"] is not None
                and e["clean"] is not None
                and e["case"] <= err_factor * e["clean"] + err_margin_m
                for e in errs
            ),
        }
    case, clean = m["case"], m["clean"]
    last = case["last_output_before_end_s"]
    return {
        "logging": last is not None and last <= END_SLACK_S,
        "pose_volume": case["pose_messages"] <= POSE_VOLUME_MAX * clean["pose_messages"],
        "steps_stop": case["steps_after_grace"] == 0,
        "wifi_fixes": None
        if clean["wifi_fixes_in_failure"] == 0
        else case["wifi_fixes_in_failure"] >= WIFI_MIN * clean["wifi_fixes_in_failure"],
    }


def describe(row: dict[str, Any]) -> str | None:
    """One line of the case's measures for the table's foot (None for a kind without any)."""
    m = row.get("measures")
    if m is None:
        return None
    if row["fault"] == "board_time_stuck":
        off = m["time_offset_after_max_ms"]
        errs = ", ".join(
            f"{s} {_m(e['case'])} vs {_m(e['clean'])} clean" for s, e in m["mean_error_after_m"].items()
        )
        return (
            f"after {m['after_s']:g} s: output times within {'-' if off is None else f'{off:.1f}'} ms of "
            f"clean ({m['imu_after_matched']}/{m['imu_after_clean']} IMU samples matched); mean error {errs}"
        )
    case, clean = m["case"], m["clean"]
    last = case["last_output_before_end_s"]
    return (
        f"from {m['failed_s'][0]:g} s: POSE {case['pose_messages']} vs {clean['pose_messages']} clean "
        f"(x{case['pose_messages'] / max(clean['pose_messages'], 1):.2f}), log {case['log_bytes'] / 1e6:.1f} vs "
        f"{clean['log_bytes'] / 1e6:.1f} MB; steps after {STEP_GRACE_S:g} s {case['steps_after_grace']}; "
        f"Wi-Fi fixes {case['wifi_fixes_in_failure']} vs {clean['wifi_fixes_in_failure']} clean "
        f"({case['wifi_fixes_accepted_in_failure']} accepted); last output "
        f"{'-' if last is None else f'{last:.1f}'} s before the end"
    )


def _m(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f} m"
