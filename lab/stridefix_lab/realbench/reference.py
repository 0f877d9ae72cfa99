"""Two textbook references for ``realbench fusion``, computed in Python from the imported walks (their
:class:`~stridefix_analyzer.datasets.rawwalk.RawWalk`, read into a :class:`.reference_sensors.Track`): what
a plain pedestrian dead reckoning and a plain Wi-Fi/PDR EKF score on the same walks, training walks,
starts and truth times as the firmware's schemes. Not schemes: the firmware never runs them.

* ``reference_pdr`` (step-and-heading PDR): each step of length K·(amax − amin)^¼ (Weinberg 2002, K
  from the training walks) along the complementary-filter heading ψ plus one constant device-to-walk
  offset per walk. From the true start (truth position at the first truth point, heading towards the next
  one) the offset = that heading minus the circular mean of ψ over the first :data:`START_STEPS` steps
  (magnetometer and gyroscope only; the one look-ahead, ≈ 2 s, averages the gait's sway); from the first fix (the first WkNN fix) the offset = the angle
  between the fixes' displacement and the dead-reckoned displacement since that fix, taken once, when
  a fix lies :data:`OFFSET_MIN_SPAN_M` from the first (0 until then; the track since the start turns
  with it). No absolute fix after the start.
* ``reference_ekf``: extended Kalman filter, state [E, N, heading bias] [m, m, rad]; prediction by the
  same steps along ψ + bias (step-length σ :data:`STEP_LENGTH_SIGMA` × length, heading σ
  :data:`STEP_HEADING_SIGMA_RAD` and bias random walk :data:`BIAS_WALK_RAD` per step); update by every
  WkNN fix, σ :data:`FIX_SIGMA_M` per axis, behind a χ² gate (:data:`GATE_CHI2`: 2 dof, 99 %); after
  :data:`MAX_REJECTS` consecutive rejections the position resets to the fix.

Both take the floor from the barometer: start floor + round(height change since the start / storey
height of the fold's site). Both emit poses at the start (not before the first IMU sample: the firmware
emits none either), at every step and (ekf) every fix; they are scored like the schemes
(:func:`.fold.score_poses`). Pure numpy; no constant is tuned per data set.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.radiomap.strides import WEINBERG_EXPONENT
from stridefix_analyzer.scoring.metrics import wrap_pi

from stridefix_lab.realbench.floors import DEFAULT_STOREY_M
from stridefix_lab.realbench.reference_sensors import Fingerprints, Track, weinberg_k

REFERENCE_PDR, REFERENCE_EKF = "reference_pdr", "reference_ekf"
NAMES = (REFERENCE_PDR, REFERENCE_EKF)
START_STEPS = 4  # ≈ 2 s of walking: averages the hand-held phone's sway over two strides
#: two fixes (σ 3 m per axis each) this far apart give the walking direction within atan(3·√2/10) ≈ 23°
#: (1σ) [m]
OFFSET_MIN_SPAN_M = 10.0
FIX_SIGMA_M = 3.0
GATE_CHI2 = 9.21  # χ²(2 dof) at 99 %
MAX_REJECTS = 3
STEP_LENGTH_SIGMA = 0.1  # Weinberg's step-length error, share of the length
STEP_HEADING_SIGMA_RAD = math.radians(5.0)  # per step: the hand-held phone's sway
BIAS_WALK_RAD = math.radians(1.0)  # per step: slow gyro drift and magnetic disturbance
START_BIAS_SIGMA_RAD = math.radians(90.0)  # from the first fix the offset is unknown


@dataclasses.dataclass(frozen=True)
class Start:
    """Where a reference starts: time [µs], position [m], floor, walking heading [rad] (NaN: unknown)."""

    t_us: int
    x_m: float
    y_m: float
    floor: int
    heading_rad: float = math.nan


def _angle(dx: float, dy: float) -> float:
    """Heading [rad, clockwise from +y] of the vector (dx, dy)."""
    return math.atan2(dx, dy)


def truth_start(track: Track) -> Start:
    """The first truth point, heading towards the next truth point at least 1 m away (NaN: none)."""
    tr = track.truth
    x, y = tr["x_m"], tr["y_m"]
    far = np.flatnonzero(np.hypot(x - x[0], y - y[0]) >= 1.0)
    h = _angle(x[far[0]] - x[0], y[far[0]] - y[0]) if len(far) else math.nan
    return Start(int(tr["t_us"][0]), float(x[0]), float(y[0]), int(tr["floor"][0]), h)


def start_offset_rad(track: Track, start: Start) -> float:
    """Device-to-walk offset from a known start heading: it minus the circular mean of ψ over the first
    :data:`START_STEPS` steps after the start (0 without a start heading or steps)."""
    psi = track.step_heading_rad[track.step_t_us > start.t_us][:START_STEPS]
    if not math.isfinite(start.heading_rad) or not len(psi):
        return 0.0
    return float(wrap_pi(start.heading_rad - math.atan2(np.sin(psi).sum(), np.cos(psi).sum())))


def first_pose_t_us(track: Track, start: Start) -> int:
    """The first pose's time: the start, but not before the first IMU sample (as the firmware, which
    emits nothing before its sensors: truth points before them stay unscored for every row)."""
    return max(int(start.t_us), int(track.imu_t_us[0]))


def floors_at(track: Track, t_us: np.ndarray, start: Start, storey_m: float) -> np.ndarray:
    """Start floor + round(barometric height change since the start / storey height)."""
    if len(track.baro_t_us) < 2:
        return np.full(len(t_us), start.floor, np.int64)
    h = np.interp(np.asarray(t_us, float), track.baro_t_us, track.height_m)
    h0 = np.interp(float(start.t_us), track.baro_t_us, track.height_m)
    return start.floor + np.rint((h - h0) / storey_m).astype(np.int64)


def _poses(
    track: Track, rows: list[tuple[int, float, float, float, float]], start: Start, storey_m: float
) -> Table:
    t, x, y, sig, hd = (np.asarray(c) for c in zip(*rows))
    return Table(
        {
            "t_us": t.astype(np.int64),
            "x_m": x,
            "y_m": y,
            "floor": floors_at(track, t, start, storey_m),
            "sigma_m": sig,
            "heading_rad": hd,
        }
    )


def run_pdr(
    track: Track, k: float, start: Start, storey_m: float, fixes: tuple[np.ndarray, np.ndarray] | None = None
) -> Table:
    """``reference_pdr`` from ``start``: poses at the start and every step after it.

    ``fixes`` (t_us, xy_m) only learn the offset (from the first fix; see the module); None: the offset
    comes from the start heading (:func:`start_offset_rad`).
    """
    after = track.step_t_us > start.t_us
    st, rng, psi = track.step_t_us[after], track.step_range_mps2[after], track.step_heading_rad[after]
    length = k * np.maximum(rng, 0.0) ** WEINBERG_EXPONENT
    offset, learned = (start_offset_rad(track, start), True) if fixes is None else (0.0, False)
    ft, fxy = fixes if fixes is not None else (np.zeros(0, np.int64), np.zeros((0, 2)))
    u = np.zeros(2)  # dead-reckoned displacement since the start, device frame (offset 0) [m]
    rows = [(first_pose_t_us(track, start), start.x_m, start.y_m, 0.0, start.heading_rad)]
    j = int(np.searchsorted(ft, start.t_us, side="right"))
    for ts, ln, p in zip(st.tolist(), length.tolist(), psi.tolist()):
        while not learned and j < len(ft) and ft[j] <= ts:  # the first fixes give the offset, once
            d = fxy[j] - (start.x_m, start.y_m)
            if math.hypot(*d) >= OFFSET_MIN_SPAN_M and math.hypot(*u) > 0:
                offset, learned = float(wrap_pi(_angle(*d) - _angle(*u))), True
            j += 1
        u += (ln * math.sin(p), ln * math.cos(p))
        c, s = math.cos(offset), math.sin(offset)
        rows.append(
            (ts, start.x_m + u[0] * c + u[1] * s, start.y_m - u[0] * s + u[1] * c, math.nan, p + offset)
        )
    return _poses(track, rows, start, storey_m)


class Ekf:
    """State [E, N, heading bias] [m, m, rad]; ψ + bias is the walking heading (see the module)."""

    def __init__(self, start: Start, bias_rad: float, pos_sigma_m: float, bias_sigma_rad: float):
        self.x = np.array([start.x_m, start.y_m, bias_rad])
        self.P = np.diag([pos_sigma_m**2, pos_sigma_m**2, bias_sigma_rad**2])
        self.rejects = 0

    def predict(self, length_m: float, psi_rad: float) -> None:
        h = psi_rad + self.x[2]
        s, c = math.sin(h), math.cos(h)
        self.x[:2] += (length_m * s, length_m * c)
        F = np.array([[1.0, 0.0, length_m * c], [0.0, 1.0, -length_m * s], [0.0, 0.0, 1.0]])
        G = np.array([[s, length_m * c], [c, -length_m * s]])
        Q = np.zeros((3, 3))
        Q[:2, :2] = G @ np.diag([(STEP_LENGTH_SIGMA * length_m) ** 2, STEP_HEADING_SIGMA_RAD**2]) @ G.T
        Q[2, 2] = BIAS_WALK_RAD**2
        self.P = F @ self.P @ F.T + Q

    def update(self, fix_m: np.ndarray) -> str:
        """Gate, update or reset with one fix [m]; returns "accepted", "rejected" or "reset"."""
        R = np.eye(2) * FIX_SIGMA_M**2
        nu = np.asarray(fix_m, float) - self.x[:2]
        S = self.P[:2, :2] + R
        if float(nu @ np.linalg.solve(S, nu)) > GATE_CHI2:
            self.rejects += 1
            if self.rejects < MAX_REJECTS:
                return "rejected"
            self.x[:2] = fix_m
            self.P[:2, :] = self.P[:, :2] = 0.0
            self.P[:2, :2] = R
            self.rejects = 0
            return "reset"
        K = np.linalg.solve(S, self.P[:2, :]).T  # P Hᵀ S⁻¹ (S symmetric)
        self.x += K @ nu
        self.P = (np.eye(3) - K[:, :2] @ np.eye(2, 3)) @ self.P
        self.P = 0.5 * (self.P + self.P.T)
        self.rejects = 0
        return "accepted"


def run_ekf(
    track: Track,
    k: float,
    start: Start,
    fixes: tuple[np.ndarray, np.ndarray],
    storey_m: float,
    true_start: bool,
) -> tuple[Table, dict[str, int]]:
    """``reference_ekf`` from ``start``: poses at the start, every step and every fix after it, and the
    count of fixes accepted, rejected and reset to."""
    if true_start:  # position known; the offset from 4 steps of ψ (5° sway each) and the truth heading
        ekf = Ekf(start, start_offset_rad(track, start), 0.0, 2 * STEP_HEADING_SIGMA_RAD)
    else:  # at the first fix, its σ; the offset unknown
        ekf = Ekf(start, 0.0, FIX_SIGMA_M, START_BIAS_SIGMA_RAD)
    after = track.step_t_us > start.t_us
    length = k * np.maximum(track.step_range_mps2[after], 0.0) ** WEINBERG_EXPONENT
    events = [
        (int(t), 0, (ln, p))
        for t, ln, p in zip(track.step_t_us[after], length, track.step_heading_rad[after])
    ]
    events += [(int(t), 1, xy) for t, xy in zip(*fixes) if t > start.t_us]
    counts = {"accepted": 0, "rejected": 0, "reset": 0}
    rows = [
        (
            first_pose_t_us(track, start),
            start.x_m,
            start.y_m,
            math.sqrt(ekf.P[0, 0] + ekf.P[1, 1]),
            start.heading_rad,
        )
    ]
    psi = start.heading_rad - ekf.x[2]
    for t, kind, what in sorted(events, key=lambda e: (e[0], e[1])):
        if kind == 0:
            ekf.predict(*what)
            psi = what[1]
        else:
            counts[ekf.update(np.asarray(what, float))] += 1
        rows.append((t, ekf.x[0], ekf.x[1], math.sqrt(ekf.P[0, 0] + ekf.P[1, 1]), psi + ekf.x[2]))
    return _poses(track, rows, start, storey_m), counts


def storey_of(floor_heights_m: Sequence[float]) -> float:
    """Storey height [m]: the median step of the fold's floor heights, else :data:`DEFAULT_STOREY_M`."""
    d = np.diff(np.asarray(floor_heights_m, float))
    d = d[np.isfinite(d) & (d > 0.5)]
    return float(np.median(d)) if len(d) else DEFAULT_STOREY_M


def run_references(
    held: Track, training: Sequence[Track], floor_heights_m: Sequence[float], true_start: bool
) -> tuple[dict[str, dict[str, Table]], dict[str, Any]]:
    """Both references on the held-out walk, trained on ``training``: run tag ("fixes", and
    "true_start" when asked) → name → pose Table; and what was learned (K, storey, fix counts)."""
    k = weinberg_k(training)
    storey = storey_of(floor_heights_m)
    ft, fxy, ffl = Fingerprints(training).locate(held)
    info: dict[str, Any] = {"K": k, "storey_m": storey, "wifi_fixes": len(ft)}
    out: dict[str, dict[str, Table]] = {}
    if not math.isfinite(k):
        info["error"] = "no Weinberg K: the training walks have no scored segment"
        return out, info
    starts: list[tuple[str, Start | None]] = [
        ("fixes", Start(int(ft[0]), float(fxy[0, 0]), float(fxy[0, 1]), int(ffl[0])) if len(ft) else None)
    ]
    if true_start:
        starts.append(("true_start", truth_start(held)))
    for tag, start in starts:
        if start is None:
            continue
        ts = tag == "true_start"
        pdr = run_pdr(held, k, start, storey, None if ts else (ft, fxy))
        ekf, counts = run_ekf(held, k, start, (ft, fxy), storey, ts)
        out[tag] = {REFERENCE_PDR: pdr, REFERENCE_EKF: ekf}
        info[f"ekf_fixes_{tag}"] = counts
    return out, info
