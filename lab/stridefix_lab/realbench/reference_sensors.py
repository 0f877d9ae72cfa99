"""The inputs of the textbook references (:mod:`.reference`) from one walk's
:class:`~stridefix_analyzer.datasets.rawwalk.RawWalk`, and what a fold learns from its training walks.

Per walk (:func:`track_of`, phase 1 of ``realbench fusion``):

* gravity = the accelerometer low-passed (first order, :data:`GRAVITY_TAU_S`), "up" in the device frame;
* device heading ψ [rad, clockwise from the map's +y] by a complementary filter (Higgins 1975): the
  gyroscope's rotation about "up" integrated, pulled towards the tilt-compensated magnetometer heading
  (east = m × up, north = up × east; the heading of the device's +y axis, as Android's azimuth) with time
  constant :data:`HEADING_TAU_S`;
* steps = peaks of the :data:`STEP_LOWPASS_HZ` low-passed |a| (2nd-order Butterworth, forward and
  backward) above :data:`STEP_MIN_PEAK_MPS2` and at least :data:`STEP_MIN_INTERVAL_S` apart, each with
  the range amax − amin of the filtered |a| since the previous step (Weinberg 2002);
* height = the barometric formula on the pressure (:func:`.floors.pressure_to_height_m`).

Per fold, from the training walks: the Weinberg K = Σ true / Σ range^¼ over their waypoint segments
(:func:`weinberg_k`: :func:`stridefix_analyzer.radiomap.strides.build_segments` and :func:`stridefix_analyzer.radiomap.strides.stride_k`, the functions the
firmware's K comes from, on these steps) and a WkNN fingerprint map (Bahl & Padmanabhan 2000, RADAR) of
their raw scans at their truth positions, linear in time between truth points (:class:`Fingerprints`: k =
:data:`WKNN_K`, Euclidean distance in dBm with :data:`MISSING_DBM` for an AP one side did not hear,
weights 1 / distance; the floor is the weighted vote of the k neighbours). realbench's firmware sites
carry a radio map of averaged cells (:mod:`.fold`); the textbook WkNN takes the training scans as they are.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from stridefix_analyzer.datasets.rawwalk import RawWalk
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.radiomap.strides import build_segments, stride_k

from stridefix_lab.realbench.floors import pressure_to_height_m

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
WKNN_K = 4
MISSING_DBM = -100.0  # an AP not heard: the receivers' noise floor [dBm]


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
        """This walk as :func:`stridefix_analyzer.radiomap.strides.build_segments` reads it."""
        tr, n = self.truth, len(self.step_t_us)
        return {
            "walk": "",
            "error": None,
            "waypoint_t_us": tr["t_us"],
            "waypoint_xy_m": np.column_stack([tr["x_m"], tr["y_m"]]),
            "step_t_us": self.step_t_us,
            "step_range_mps2": self.step_range_mps2,
            "step_length_m": np.zeros(n),
            "import": {"imu_t_first_us": self.imu_t_us[0], "imu_t_last_us": self.imu_t_us[1]},
        }


def _lowpass1(x: np.ndarray, dt_s: np.ndarray, tau_s: float) -> np.ndarray:
    """First-order low-pass along axis 0, started at the first sample."""
    y = np.empty_like(x)
    y[0] = x[0]
    alpha = dt_s / (tau_s + dt_s)
    for i in range(1, len(x)):
        y[i] = y[i - 1] + alpha[i] * (x[i] - y[i - 1])
    return y


def _butter2_filtfilt(x: np.ndarray, fs_hz: float, fc_hz: float) -> np.ndarray:
    """2nd-order Butterworth low-pass (scipy.signal.butter: bilinear transform), run forward then
    backward (zero phase), each pass started at rest on its first sample."""
    from scipy import signal

    b, a = signal.butter(2, min(fc_hz, 0.45 * fs_hz), fs=fs_hz)
    zi = signal.lfilter_zi(b, a)
    forward = signal.lfilter(b, a, x, zi=zi * x[0])[0]
    return np.asarray(signal.lfilter(b, a, forward[::-1], zi=zi * forward[-1])[0][::-1])


def device_heading(
    t_us: np.ndarray,
    accel_mps2: np.ndarray,
    gyro_radps: np.ndarray,
    mag_t_us: np.ndarray,
    field_ut: np.ndarray,
) -> np.ndarray:
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
    """K = Σ true distance / Σ range^¼ over the training walks' scored waypoint segments (:mod:`stridefix_analyzer.radiomap.strides`)."""
    seg = build_segments([tr.segments_input() for tr in training])
    return stride_k(seg, seg["excluded"] == "")


class Fingerprints:
    """The training walks' scans at their truth positions (linear in time between truth points)."""

    def __init__(self, training: Sequence[Track]):
        rows: list[np.ndarray] = []
        aps: list[np.ndarray] = []
        dbm: list[np.ndarray] = []
        xy: list[np.ndarray] = []
        floor: list[np.ndarray] = []
        for tr in training:
            tt, ts = tr.truth["t_us"], tr.scan_t_us
            if not len(tt) or not len(ts):
                continue
            inside = (ts >= tt[0]) & (ts <= tt[-1])
            scan_of_row = np.repeat(np.arange(len(ts)), np.diff(tr.scan_bounds))
            keep = inside[scan_of_row]
            renum = np.cumsum(inside) - 1 + int(sum(len(x) for x in xy))
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
        n = len(track.scan_t_us)
        scan = np.repeat(np.arange(n), np.diff(track.scan_bounds))
        col = np.array([self.ap.get(b, -1) for b in track.bssid.tolist()], np.int64)
        known = col >= 0
        heard = np.bincount(scan[known], minlength=n) > 0
        if not len(self.db) or not heard.any():
            return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0, np.int64)
        q = np.full((n, len(self.ap)), MISSING_DBM)
        q[scan[known], col[known]] = track.rssi_dbm[known]
        # APs of the scan the map never heard: (rssi − missing)² against every fingerprint
        extra = np.bincount(scan[~known], weights=(track.rssi_dbm[~known] - MISSING_DBM) ** 2, minlength=n)
        d2 = (self.db**2).sum(axis=1)[None, :] - 2 * q @ self.db.T + ((q**2).sum(axis=1) + extra)[:, None]
        d = np.sqrt(np.maximum(d2[heard], 0.0))
        nn = np.argsort(d, axis=1)[:, :WKNN_K]
        w = 1.0 / np.maximum(np.take_along_axis(d, nn, axis=1), 1e-6)
        xy = np.einsum("ik,ikj->ij", w, self.xy_m[nn]) / w.sum(axis=1, keepdims=True)
        lo = int(self.floor.min())
        votes = np.zeros((len(nn), int(self.floor.max()) - lo + 1))
        np.add.at(votes, (np.arange(len(nn))[:, None], (self.floor[nn] - lo).astype(np.int64)), w)
        return track.scan_t_us[heard].astype(np.int64), xy, votes.argmax(axis=1).astype(np.int64) + lo
