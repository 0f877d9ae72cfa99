"""Two textbook references for ``realbench fusion``, computed in Python from the imported walks: what a
plain pedestrian dead reckoning and a plain Wi-Fi/PDR EKF score on the same walks, starts and truth.

Phase 1 (:func:`track_of`, once per walk, from its :class:`~stridefix_analyzer.datasets.rawwalk.RawWalk`):

* gravity = the accelerometer low-passed (first order, :data:`GRAVITY_TAU_S`), "up" in the device frame;
* device heading ψ [rad, clockwise from the map's +y] by a complementary filter: the gyroscope's
  rotation about "up" integrated, pulled towards the tilt-compensated magnetometer heading (east = m × up,
  north = up × east; the heading of the device's +y axis, Android's azimuth) with time constant
  :data:`HEADING_TAU_S`;
* steps = peaks of the :data:`STEP_LOWPASS_HZ` low-passed |a| (2nd-order Butterworth, forward and
  backward) above :data:`STEP_MIN_PEAK_MPS2` and at least :data:`STEP_MIN_INTERVAL_S` apart, with the
  range amax − amin of the filtered |a| since the previous step (Weinberg 2002);
* height = the barometric formula on the pressure (:func:`.floors.pressure_to_height_m`).

Per fold (:func:`run_references`): the Weinberg K = Σ true / Σ range^¼ over the training walks'
waypoint segments (:mod:`.strides`, the function the firmware's K comes from, on these steps); a WkNN
fingerprint map of the training walks' raw scans at their interpolated truth positions (k =
:data:`WKNN_K`, Euclidean in dBm with :data:`MISSING_DBM` for an unheard AP, weights 1 / distance);
the floor = start floor + round(barometric height change / storey height of the fold's site).

* ``reference_pdr``: steps of length K·range^¼ along ψ + one constant device-to-walk offset per walk:
  from the true start, the truth heading (first truth point → the next) minus the circular mean of ψ over
  the first :data:`START_STEPS` steps; from the first fix, the angle between the fixes' displacement and
  the dead-reckoned displacement since the first fix, once the fixes are :data:`OFFSET_MIN_SPAN_M` apart
  (0 until then). No absolute fix after the start.
* ``reference_ekf``: EKF (state E, N, heading bias) predicting with the same steps, updated by every WkNN
  fix (σ :data:`FIX_SIGMA_M` per axis) behind a χ² gate (:data:`GATE_CHI2`, 2 dof 99 %), reset to the fix
  after :data:`MAX_REJECTS` consecutive rejections.

Pure numpy; no constant is tuned per data set.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from stridefix_analyzer.datasets.rawwalk import RawWalk
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.realbench.floors import DEFAULT_STOREY_M, pressure_to_height_m
from stridefix_analyzer.realbench.strides import WEINBERG_EXPONENT, build_segments, stride_k

REFERENCE_PDR, REFERENCE_EKF = "reference_pdr", "reference_ekf"
NAMES = (REFERENCE_PDR, REFERENCE_EKF)
G_MPS2 = 9.80665
#: gravity = accelerometer low-passed over a few gait cycles (a step lasts ~0.5 s) [s]
GRAVITY_TAU_S = 1.0
HEADING_TAU_S = 20.0
#: gait acceleration lies below ~3 Hz (cadence ≤ ~2.5 steps/s) [Hz]
STEP_LOWPASS_HZ = 3.0
#: a step's peak must exceed 1 g: the heel strike pushes |a| above gravity [m/s²]
STEP_MIN_PEAK_MPS2 = 1.05 * G_MPS2
#: human walking cadence stays under ~200 steps/min, so two steps are ≥ 0.3 s apart [s]
STEP_MIN_INTERVAL_S = 0.3
START_STEPS = 4  # ≈ 2 s of walking: averages the hand-held phone's sway over two strides
#: fixes this far apart (≈ 3 × the fix σ·√2) fix the device-to-walk offset within ~25° [m]
OFFSET_MIN_SPAN_M = 10.0
WKNN_K = 4
MISSING_DBM = -100.0  # an AP not heard: the receivers' noise floor [dBm]
FIX_SIGMA_M = 3.0
GATE_CHI2 = 9.21  # χ²(2 dof) at 99 %
MAX_REJECTS = 3
STEP_LENGTH_SIGMA = 0.1  # Weinberg's step-length error, share of the length
STEP_HEADING_SIGMA_RAD = math.radians(5.0)  # per step: the hand-held phone's sway
BIAS_WALK_RAD = math.radians(1.0)  # per step: slow gyro drift and magnetic disturbance
START_BIAS_SIGMA_RAD = math.radians(90.0)  # from the first fix the offset is unknown


@dataclasses.dataclass(frozen=True)
class Track:
    """What the references read from one walk (phase 1): steps, heights, scans and truth (µs, m, rad)."""

    imu_t_us: tuple[int, int]  # first and last IMU sample
    step_t_us: np.ndarray
    step_range_mps2: np.ndarray
    step_heading_rad: np.ndarray  # device heading ψ at each step
    baro_t_us: np.ndarray
    height_m: np.ndarray
    scan_t_us: np.ndarray  # (n_scans,)
    scan_bounds: np.ndarray  # (n_scans + 1,) rows of scan i in bssid / rssi_dbm
    bssid: np.ndarray
    rssi_dbm: np.ndarray
    truth: Table  # t_us, x_m, y_m, floor

    def segments_input(self) -> dict[str, Any]:
        """This walk as :func:`.strides.build_segments` reads it."""
        tr, n = self.truth, len(self.step_t_us)
        return {
            "walk": "", "error": None, "waypoint_t_us": tr["t_us"],
            "waypoint_xy_m": np.column_stack([tr["x_m"], tr["y_m"]]), "step_t_us": self.step_t_us,
            "step_range_mps2": self.step_range_mps2, "step_length_m": np.zeros(n),
            "import": {"imu_t_first_us": self.imu_t_us[0], "imu_t_last_us": self.imu_t_us[1]},
        }  # fmt: skip


def _lowpass1(x: np.ndarray, dt_s: np.ndarray, tau_s: float) -> np.ndarray:
    """First-order low-pass along axis 0, started at the first sample."""
    y = np.empty_like(x)
    y[0] = x[0]
    alpha = dt_s / (tau_s + dt_s)
    for i in range(1, len(x)):
        y[i] = y[i - 1] + alpha[i] * (x[i] - y[i - 1])
    return y


def _butter2_filtfilt(x: np.ndarray, fs_hz: float, fc_hz: float) -> np.ndarray:
    """2nd-order Butterworth low-pass (bilinear transform), run forward then backward (zero phase)."""
    k = math.tan(math.pi * min(fc_hz, 0.45 * fs_hz) / fs_hz)
    n = 1.0 / (1.0 + math.sqrt(2.0) * k + k * k)
    b0, b1, b2 = k * k * n, 2 * k * k * n, k * k * n
    a1, a2 = 2.0 * (k * k - 1.0) * n, (1.0 - math.sqrt(2.0) * k + k * k) * n

    def one(v: list[float]) -> list[float]:
        out, x1, x2, y1, y2 = [], v[0], v[0], v[0], v[0]
        for xi in v:
            yi = b0 * xi + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2
            out.append(yi)
            x2, x1, y2, y1 = x1, xi, y1, yi
        return out

    return np.asarray(one(one(x.tolist())[::-1])[::-1])


def device_heading(t_us: np.ndarray, accel_mps2: np.ndarray, gyro_radps: np.ndarray,
                   mag_t_us: np.ndarray, field_ut: np.ndarray) -> np.ndarray:  # fmt: skip
    """Complementary-filter heading ψ [rad] of the device's +y axis at the IMU times (see the module)."""
    dt = np.diff(t_us, prepend=t_us[0]) / 1e6
    up = _lowpass1(accel_mps2, dt, GRAVITY_TAU_S)
    up /= np.maximum(np.linalg.norm(up, axis=1, keepdims=True), 1e-9)
    rate_radps = -np.einsum("ij,ij->i", gyro_radps, up)  # clockwise about up = heading rate
    if len(mag_t_us):
        m = np.column_stack([np.interp(t_us, mag_t_us, field_ut[:, j]) for j in range(3)])
        east = np.cross(m, up)
        north = np.cross(up, east)
        mag = np.arctan2(east[:, 1], north[:, 1])
    else:
        mag = np.full(len(t_us), np.nan)
    psi = np.empty(len(t_us))
    psi[0] = mag[0] if np.isfinite(mag[0]) else 0.0
    gain = dt / HEADING_TAU_S
    for i in range(1, len(t_us)):
        p = psi[i - 1] + rate_radps[i] * dt[i]
        if math.isfinite(mag[i]):
            p += gain[i] * (((mag[i] - p + math.pi) % (2 * math.pi)) - math.pi)
        psi[i] = p
    return psi


def detect_steps(t_us: np.ndarray, accel_mps2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Step indices into the IMU samples and each step's range amax − amin [m/s²] (see the module)."""
    if len(t_us) < 3:
        return np.zeros(0, np.int64), np.zeros(0)
    fs = 1e6 / max(float(np.median(np.diff(t_us))), 1.0)
    a = _butter2_filtfilt(np.linalg.norm(accel_mps2, axis=1), fs, STEP_LOWPASS_HZ)
    cand = np.flatnonzero((a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:]) & (a[1:-1] > STEP_MIN_PEAK_MPS2)) + 1
    kept: list[int] = []
    for i in cand:
        if kept and (t_us[i] - t_us[kept[-1]]) < STEP_MIN_INTERVAL_S * 1e6:
            if a[i] > a[kept[-1]]:
                kept[-1] = int(i)
        else:
            kept.append(int(i))
    idx = np.asarray(kept, np.int64)
    lo = np.concatenate([[0], idx[:-1]])
    rng = np.array([a[s : e + 1].max() - a[s : e + 1].min() for s, e in zip(lo, idx)])
    return idx, rng


def track_of(raw: RawWalk) -> Track:
    """Phase 1 of the references for one walk (see the module docstring)."""
    imu, t = raw.imu, raw.imu["t_us"].astype(np.int64)
    if len(t) >= 3:
        psi = device_heading(t, imu["accel_mps2"], imu["gyro_radps"], raw.mag["t_us"], raw.mag["field_ut"])
        idx, rng = detect_steps(t, imu["accel_mps2"])
        first_last = (int(t[0]), int(t[-1]))
    else:
        psi, idx, rng, first_last = np.zeros(0), np.zeros(0, np.int64), np.zeros(0), (0, 0)
    tr = raw.truth
    return Track(
        imu_t_us=first_last,
        step_t_us=t[idx] if len(t) else np.zeros(0, np.int64),
        step_range_mps2=rng,
        step_heading_rad=psi[idx] if len(psi) else np.zeros(0),
        baro_t_us=raw.baro["t_us"].astype(np.int64),
        height_m=pressure_to_height_m(raw.baro["pressure_pa"]),
        scan_t_us=raw.scan_t_us(),
        scan_bounds=raw.scan_bounds(),
        bssid=raw.wifi["bssid"].astype(np.int64),
        rssi_dbm=raw.wifi["rssi_dbm"].astype(float),
        truth=Table({c: tr[c] for c in ("t_us", "x_m", "y_m", "floor")}),
    )


def weinberg_k(training: Sequence[Track]) -> float:
    """K = Σ true distance / Σ range^¼ over the training walks' scored waypoint segments (:mod:`.strides`)."""
    seg = build_segments([tr.segments_input() for tr in training])
    return stride_k(seg, seg["excluded"] == "")


class Fingerprints:
    """The training walks' scans at their truth positions (linear in time between truth points)."""

    def __init__(self, training: Sequence[Track]):
        rows, aps, dbm, xy, floor = [], [], [], [], []
        for tr in training:
            tt, ts = tr.truth["t_us"], tr.scan_t_us
            if not len(tt) or not len(ts):
                continue
            inside = (ts >= tt[0]) & (ts <= tt[-1])
            scan_of_row = np.repeat(np.arange(len(ts)), np.diff(tr.scan_bounds))
            keep = inside[scan_of_row]
            renum = np.cumsum(inside) - 1 + sum(len(x) for x in xy)
            rows.append(renum[scan_of_row[keep]])
            aps.append(tr.bssid[keep])
            dbm.append(tr.rssi_dbm[keep])
            xy.append(np.column_stack([np.interp(ts[inside], tt, tr.truth[c]) for c in ("x_m", "y_m")]))
            near = np.clip(np.searchsorted(tt, ts[inside]), 1, max(len(tt) - 1, 1))
            prev_closer = (ts[inside] - tt[near - 1]) <= (tt[np.minimum(near, len(tt) - 1)] - ts[inside])
            floor.append(tr.truth["floor"][np.where(prev_closer, near - 1, np.minimum(near, len(tt) - 1))])
        cat = lambda v, dt: np.concatenate(v).astype(dt) if v else np.zeros(0, dt)  # noqa: E731
        ap_ids, col = np.unique(cat(aps, np.int64), return_inverse=True)
        self.ap = {int(b): j for j, b in enumerate(ap_ids)}
        self.xy_m = np.concatenate(xy) if xy else np.zeros((0, 2))
        self.floor = cat(floor, np.int64)
        self.db = np.full((len(self.xy_m), len(ap_ids)), MISSING_DBM)
        self.db[cat(rows, np.int64), col.reshape(-1)] = cat(dbm, float)

    def locate(self, track: Track) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """WkNN fix of every scan of ``track`` sharing an AP with the map: (t_us, xy_m (n, 2), floor)."""
        t, xy, fl = [], [], []
        if not len(self.db):
            return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0, np.int64)
        sq_db = (self.db**2).sum(axis=1)
        for i, ts in enumerate(track.scan_t_us):
            s = slice(int(track.scan_bounds[i]), int(track.scan_bounds[i + 1]))
            q = np.full(len(self.ap), MISSING_DBM)
            known = [(self.ap[b], r) for b, r in zip(track.bssid[s].tolist(), track.rssi_dbm[s].tolist())
                     if b in self.ap]  # fmt: skip
            if not known:
                continue
            q[[j for j, _ in known]] = [r for _, r in known]
            extra = sum(
                (r - MISSING_DBM) ** 2 for b, r in zip(track.bssid[s], track.rssi_dbm[s]) if b not in self.ap
            )
            d = np.sqrt(np.maximum(sq_db - 2 * self.db @ q + q @ q + extra, 0.0))
            nn = np.argsort(d)[:WKNN_K]
            w = 1.0 / np.maximum(d[nn], 1e-6)
            t.append(int(ts))
            xy.append(w @ self.xy_m[nn] / w.sum())
            fl.append(
                int(np.bincount(self.floor[nn] - self.floor.min(), weights=w).argmax() + self.floor.min())
            )
        return np.asarray(t, np.int64), np.asarray(xy, float).reshape(-1, 2), np.asarray(fl, np.int64)


@dataclasses.dataclass(frozen=True)
class Start:
    """Where a reference starts: time [µs], position [m], floor, walking heading [rad] (NaN: unknown)."""

    t_us: int
    x_m: float
    y_m: float
    floor: int
    heading_rad: float = math.nan


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


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
    return _wrap(start.heading_rad - math.atan2(np.sin(psi).sum(), np.cos(psi).sum()))


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
    return Table({"t_us": t.astype(np.int64), "x_m": x, "y_m": y, "floor": floors_at(track, t, start, storey_m),
                  "sigma_m": sig, "heading_rad": hd})  # fmt: skip


def run_pdr(track: Track, k: float, start: Start, storey_m: float, fixes: tuple[np.ndarray, np.ndarray] | None = None) -> Table:  # fmt: skip
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
    rows = [(start.t_us, start.x_m, start.y_m, 0.0, start.heading_rad)]
    j = int(np.searchsorted(ft, start.t_us, side="right"))
    for ts, ln, p in zip(st.tolist(), length.tolist(), psi.tolist()):
        while not learned and j < len(ft) and ft[j] <= ts:  # the first fixes give the offset, once
            d = fxy[j] - (start.x_m, start.y_m)
            if math.hypot(*d) >= OFFSET_MIN_SPAN_M and math.hypot(*u) > 0:
                offset, learned = _wrap(_angle(*d) - _angle(*u)), True
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


def run_ekf(track: Track, k: float, start: Start, fixes: tuple[np.ndarray, np.ndarray], storey_m: float,
            true_start: bool) -> tuple[Table, dict[str, int]]:  # fmt: skip
    """``reference_ekf`` from ``start``: poses at the start, every step and every fix after it, and the
    count of fixes accepted, rejected and reset to."""
    if true_start:
        ekf = Ekf(start, start_offset_rad(track, start), 0.0, 2 * STEP_HEADING_SIGMA_RAD)
    else:
        ekf = Ekf(start, 0.0, FIX_SIGMA_M, START_BIAS_SIGMA_RAD)
    after = track.step_t_us > start.t_us
    length = k * np.maximum(track.step_range_mps2[after], 0.0) ** WEINBERG_EXPONENT
    events = [
        (int(t), 0, (ln, p))
        for t, ln, p in zip(track.step_t_us[after], length, track.step_heading_rad[after])
    ]
    events += [(int(t), 1, xy) for t, xy in zip(*fixes) if t > start.t_us]
    counts = {"accepted": 0, "rejected": 0, "reset": 0}
    rows = [(start.t_us, start.x_m, start.y_m, math.sqrt(ekf.P[0, 0] + ekf.P[1, 1]), start.heading_rad)]
    psi = start.heading_rad - ekf.x[2]
    for t, kind, what in sorted(events, key=lambda e: (e[0], e[1])):
        if kind == 0:
            ekf.predict(*what)
            psi = what[1]
        else:
            counts[ekf.update(what)] += 1
        rows.append((t, ekf.x[0], ekf.x[1], math.sqrt(ekf.P[0, 0] + ekf.P[1, 1]), psi + ekf.x[2]))
    return _poses(track, rows, start, storey_m), counts


def storey_of(floor_heights_m: Sequence[float]) -> float:
    """Storey height [m]: the median step of the fold's floor heights, else :data:`DEFAULT_STOREY_M`."""
    d = np.diff(np.asarray(floor_heights_m, float))
    d = d[np.isfinite(d) & (d > 0.5)]
    return float(np.median(d)) if len(d) else DEFAULT_STOREY_M


def run_references(held: Track, training: Sequence[Track], floor_heights_m: Sequence[float],
                   true_start: bool) -> tuple[dict[str, dict[str, Table]], dict[str, Any]]:  # fmt: skip
    """Both references on the held-out walk, trained on ``training``: run tag ("fixes", and
    "true_start" when asked) → name → pose Table; and what was learned (K, storey, fix counts)."""
    k = weinberg_k(training)
    storey = storey_of(floor_heights_m)
    ft, fxy, ffl = Fingerprints(training).locate(held)
    info: dict[str, Any] = {"K": k, "storey_m": storey, "wifi_fixes": len(ft)}
    out: dict[str, dict[str, Table]] = {}
    if not math.isfinite(k) or len(held.step_t_us) == 0:
        info["error"] = "no Weinberg K or no steps"
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
