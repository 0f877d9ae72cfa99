"""``stridefix-lab bench perf``'s Python peers: the ``ahrs`` package's Madgwick and scikit-learn's KNN.

Both run in Python, so callgrind instruction counts would compare an interpreter with a C function;
these rows are wall times on this machine (informative, no budget), with what each one covers:

* **attitude** (:func:`measure_madgwick_peer`): the sensors walk's samples (``sf_core_cost samples``,
  100 Hz IMU, accel [m/s²], gyro [rad/s], field [µT] of the latest 50 Hz MAG sample on every line) through
  ``ahrs.filters.Madgwick`` (MARG: gyro + accel + mag on every sample, its default gain 0.041, started at
  the TRIAD attitude of the first sample in Madgwick's own frame, x north, z up) and through x-io
  Fusion's Python API (``imufusion.Ahrs.update``, the same loop as perf.py's callgrind peer). Wall time
  per sample is the median of :data:`REPEATS` runs of the whole walk over its samples, the sample file's
  parsing left out; Madgwick's is the batch constructor (its Python loop over ``updateMARG``), Fusion's
  the Python loop of one ``update`` call per sample (so mostly the call's overhead). Agreement: the RMS
  of the wrapped yaw difference [deg] between the two after :data:`SETTLE_S` s (Fusion's start-up
  ramp). The harness's field is constant in the body frame while the gyro turns, so the yaw is a tug
  of war between gyro and magnetometer: the agreement says how alike the two weigh them, not accuracy.
  **Ours against Fusion** (the budget "heading agrees with Fusion"): with ``ours_yaw`` (the lines of
  ``sf_core_cost yaw``, our attitude's device yaw after each IMU sample of the same walk, its MAG
  sample included) the RMS, max and mean of the wrapped difference ours − Fusion after
  :data:`SETTLE_S`; Fusion runs in its default NWU frame (yaw 0 with body x north), ours in ENU (yaw 0
  with body x east), so Fusion's yaw + 90° is compared.
* **Wi-Fi** (:func:`measure_knn_peer`): ``sf_core_cost wifidump`` writes the harness's synthetic map
  (2 m grid, one AP per 40 m², 3 scans per RP) and scans with each scan's C fix; the map becomes a dense
  RP × AP matrix at the matcher's fill (−100 dBm for an AP missing at an RP or in a scan) over every map
  AP, the same fingerprint the C WkNN (``fingerprint_map_level`` 1, fill mode) compares: every entry is
  heard by all 3 scans of its RP (level = mean) and above ``min_rssi_dbm``, and every scan reading is
  above −80 dBm. ``KNeighborsRegressor(n_neighbors=3, weights="distance")`` fits it to the RP positions
  and predicts each scan. Ours: ``sf_fingerprint_match`` (WkNN k = 3, 1/d weights) with stridefixd's
  pre-selection (default) and with the full visit (``full``, the exact WkNN sklearn also computes).
  Mean error [m] against the scan's true position; queries/s from the wall time inside the matcher
  calls (C, ``match_s``; the query's construction from the readings included) and inside ``predict``
  (sklearn, on the dense queries already built: one call for all scans, and one call per scan
  for the first :data:`SINGLE_SCANS`).
"""

from __future__ import annotations

import math
import statistics
import subprocess
import time
from pathlib import Path
from typing import Any

import numpy as np

from stridefix_lab.stages import StageError

REPEATS = 3
SETTLE_S = 5.0
SAMPLE_RATE_HZ = 100.0
#: ours (ENU, yaw from east) minus Fusion's default NWU yaw (from north), in the same body [deg]
NWU_TO_ENU_DEG = 90.0
#: the matcher's fingerprint_fill_dbm default (firmware/core/sf_params.h)
FILL_DBM = -100.0
KNN_RPS = 2000
KNN_SCANS = 300
#: scans predicted one call each (the rate of a caller with one scan at a time)
SINGLE_SCANS = 100
STANDARD_GRAVITY = 9.80665


def _median_wall_s(fn: Any, repeats: int) -> tuple[float, Any]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def _yaw_deg(q_wxyz: np.ndarray) -> np.ndarray:
    w, x, y, z = q_wxyz.T
    return np.degrees(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def _triad_q0(acc: np.ndarray, mag: np.ndarray) -> np.ndarray:
    """Body-to-earth quaternion (w, x, y, z) of Madgwick's frame (x magnetic north, z up) from one sample."""
    from scipy.spatial.transform import Rotation  # noqa: PLC0415 - bench-only dependency

    z = acc / np.linalg.norm(acc)
    x = mag - (mag @ z) * z
    x /= np.linalg.norm(x)
    qx, qy, qz, qw = Rotation.from_matrix(np.vstack([x, np.cross(z, x), z])).as_quat()
    return np.array([qw, qx, qy, qz])


def _wrapped_deg(a: np.ndarray) -> np.ndarray:
    return (a + 180.0) % 360.0 - 180.0


def read_yaw(path: Path, t_s: np.ndarray) -> np.ndarray:
    """Our yaw [deg] from a ``sf_core_cost yaw`` file (``t_s yaw_rad`` per IMU sample), checked to be on
    the samples' times ``t_s``."""
    y = np.loadtxt(path, ndmin=2)
    if y.shape != (len(t_s), 2) or not np.allclose(y[:, 0], t_s, rtol=0.0, atol=1e-5):
        raise StageError(
            f"perf peers: {path}: want 't_s yaw_rad' on the {len(t_s)} sample times, got {y.shape}"
        )
    return np.degrees(y[:, 1])


def measure_madgwick_peer(
    samples: Path, repeats: int = REPEATS, ours_yaw: Path | None = None
) -> dict[str, Any]:
    """Madgwick (ahrs) and Fusion (imufusion's Python API) on the samples file: wall time per sample and
    their yaw agreement, and with ``ours_yaw`` (a ``sf_core_cost yaw`` file of the same walk) ours
    against Fusion's (module docstring)."""
    import ahrs  # noqa: PLC0415 - bench-only dependencies
    import imufusion  # noqa: PLC0415
    from ahrs.filters import Madgwick  # noqa: PLC0415

    d = np.loadtxt(samples, ndmin=2)
    if d.shape[1] != 10 or len(d) < 2:
        raise StageError(
            f"perf peers: {samples}: want rows of 10 columns (t, accel, gyro, field), got {d.shape}"
        )
    acc, gyr, mag = d[:, 1:4], d[:, 4:7], d[:, 7:10]
    q0 = _triad_q0(acc[0], mag[0])

    def madgwick() -> np.ndarray:
        return Madgwick(gyr=gyr, acc=acc, mag=mag, frequency=SAMPLE_RATE_HZ, q0=q0).Q

    acc_g, gyr_dps = acc / STANDARD_GRAVITY, np.degrees(gyr)

    def fusion() -> np.ndarray:
        f = imufusion.Ahrs()
        f.set_sample_period(1.0 / SAMPLE_RATE_HZ)
        q = np.empty((len(d), 4))
        for i in range(len(d)):
            f.update(gyr_dps[i], acc_g[i], mag[i])
            q[i] = f.get_quaternion()
        return q

    m_s, q_m = _median_wall_s(madgwick, repeats)
    f_s, q_f = _median_wall_s(fusion, repeats)
    settled = d[:, 0] - d[0, 0] >= SETTLE_S
    yaw_f = _yaw_deg(q_f)
    dyaw = _wrapped_deg(_yaw_deg(q_m) - yaw_f)
    n = len(d)
    ours: dict[str, Any] = {}
    if ours_yaw is not None:
        dours = _wrapped_deg(read_yaw(ours_yaw, d[:, 0]) - (yaw_f + NWU_TO_ENU_DEG))[settled]
        ours = {
            "ours_vs_fusion": (
                f"our attitude's yaw (sf_core_cost yaw, ENU) - Fusion's (NWU) + {NWU_TO_ENU_DEG:.0f} deg, wrapped, "
                f"over the {int(settled.sum())} samples after {SETTLE_S:.0f} s"
            ),
            "ours_vs_fusion_yaw_rms_deg": float(np.sqrt(np.mean(dours**2))),
            "ours_vs_fusion_yaw_max_abs_deg": float(np.max(np.abs(dours))),
            "ours_vs_fusion_yaw_mean_deg": float(np.mean(dours)),
        }
    return ours | {
        "measured": (
            f"wall time per IMU sample, median of {repeats} runs over the {n} samples of sf_core_cost samples "
            f"(gyro + accel + mag on every sample at {SAMPLE_RATE_HZ:.0f} Hz), file parsing excluded; "
            "yaw agreement = RMS of the wrapped yaw difference Madgwick - Fusion after "
            f"{SETTLE_S:.0f} s"
        ),
        "samples": n,
        "madgwick": f"ahrs {ahrs.__version__} filters.Madgwick (MARG, gain 0.041, TRIAD start), batch constructor",
        "madgwick_us_per_sample": 1e6 * m_s / n,
        "fusion": "imufusion Ahrs.update + get_quaternion, one Python call per sample",
        "fusion_python_us_per_sample": 1e6 * f_s / n,
        "yaw_rms_diff_deg": float(np.sqrt(np.mean(dyaw[settled] ** 2))),
        "yaw_max_abs_diff_deg": float(np.max(np.abs(dyaw[settled]))),
    }


def read_wifidump(path: Path) -> dict[str, np.ndarray]:
    """The dense fingerprints of a ``sf_core_cost wifidump`` file (module docstring): ``map_dbm``
    [n_rp, n_ap], ``rp_xy_m``, ``query_dbm`` [n_scans, n_ap], ``truth_xy_m``, ``fix_xy_m`` and
    ``fix_ok`` (the C matcher's)."""
    rps: list[tuple[float, float]] = []
    entries: list[tuple[int, int, float]] = []
    scans: list[list[str]] = []
    for lineno, line in enumerate(path.read_text().splitlines(), 1):
        f = line.split()
        if not f:
            continue
        if f[0] == "rp" and len(f) == 4 and int(f[1]) == len(rps):
            rps.append((float(f[2]), float(f[3])))
        elif f[0] == "e" and len(f) == 4:
            entries.append((int(f[1]), int(f[2]), float(f[3])))
        elif f[0] == "q" and len(f) >= 7 and len(f) == 7 + 2 * int(f[6]):
            scans.append(f[1:])
        else:
            raise StageError(f"perf peers: {path}:{lineno}: not an rp, e or q line: {line[:80]!r}")
    if not rps or not entries or not scans:
        raise StageError(f"perf peers: {path}: {len(rps)} RPs, {len(entries)} entries, {len(scans)} scans")
    e = np.array(entries)
    n_ap = int(e[:, 1].max()) + 1
    map_dbm = np.full((len(rps), n_ap), FILL_DBM)
    map_dbm[e[:, 0].astype(int), e[:, 1].astype(int)] = e[:, 2]
    query = np.full((len(scans), n_ap), FILL_DBM)
    for i, s in enumerate(scans):
        ap = np.array(s[6::2], dtype=int)
        if ap.size and ap.max() >= n_ap:
            raise StageError(f"perf peers: {path}: scan {i} hears AP {ap.max()}, the map has {n_ap}")
        query[i, ap] = np.array(s[7::2], dtype=float)
    q = np.array([s[:5] for s in scans], dtype=float)
    return {
        "map_dbm": map_dbm,
        "rp_xy_m": np.array(rps),
        "query_dbm": query,
        "truth_xy_m": q[:, 0:2],
        "fix_ok": q[:, 2] != 0,
        "fix_xy_m": q[:, 3:5],
    }


def _c_matcher(harness: Path, out: Path, n_rp: int, n_scans: int, full: bool) -> dict[str, Any]:
    import json  # noqa: PLC0415

    dump = out / f"perf.wifidump{'.full' if full else ''}.txt"
    cmd = [str(harness), "wifidump", str(n_rp), str(n_scans), str(dump), *(["full"] if full else [])]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise StageError(f"perf peers: {' '.join(cmd)} failed ({proc.returncode}): {proc.stderr[-400:]}")
    return {"summary": json.loads(proc.stdout), "dump": read_wifidump(dump)}


def _errors_m(xy: np.ndarray, truth: np.ndarray) -> np.ndarray:
    return np.hypot(*(xy - truth).T)


def measure_knn_peer(
    harness: Path, out: Path, n_rp: int = KNN_RPS, n_scans: int = KNN_SCANS, repeats: int = REPEATS
) -> dict[str, Any]:
    """scikit-learn's KNeighborsRegressor against sf_fingerprint_match on the harness's map and scans."""
    out.mkdir(parents=True, exist_ok=True)
    pre = _c_matcher(harness, out, n_rp, n_scans, full=False)
    full = _c_matcher(harness, out, n_rp, n_scans, full=True)
    doc = compare_knn(pre, full, repeats)
    doc["measured"] = (
        f"{doc['scans']} scans on the harness's synthetic map (sf_core_cost wifidump {n_rp} {n_scans}); "
        + doc["measured"]
    )
    return doc


def compare_knn(pre: dict[str, Any], full: dict[str, Any], repeats: int = REPEATS) -> dict[str, Any]:
    """scikit-learn's KNeighborsRegressor on one wifidump's dense fingerprints against the C matcher's
    fixes in it, with the pre-selection (``pre``) and the full visit (``full``): each a dict of the
    harness's JSON ``summary`` (``scans``, ``match_s``) and its ``dump`` (:func:`read_wifidump`)."""
    import sklearn  # noqa: PLC0415 - bench-only dependency
    from sklearn.neighbors import KNeighborsRegressor  # noqa: PLC0415

    d = pre["dump"]
    if not np.array_equal(d["query_dbm"], full["dump"]["query_dbm"]):
        raise StageError("perf peers: the harness's pre-selection and full-visit runs scanned differently")
    truth = d["truth_xy_m"]
    knn = KNeighborsRegressor(n_neighbors=3, weights="distance")
    t0 = time.perf_counter()
    knn.fit(d["map_dbm"], d["rp_xy_m"])
    fit_s = time.perf_counter() - t0
    batch_s, pred = _median_wall_s(lambda: knn.predict(d["query_dbm"]), repeats)
    # one call per scan costs ~12 ms each (the call's checks, not the search): the first SINGLE_SCANS
    rows = [d["query_dbm"][i : i + 1] for i in range(min(SINGLE_SCANS, len(truth)))]
    single_s, _ = _median_wall_s(lambda: [knn.predict(r) for r in rows], repeats)
    err_knn = _errors_m(pred, truth)
    ours = {}
    for name, run in (("preselect", pre), ("full_visit", full)):
        dd, s = run["dump"], run["summary"]
        ok = dd["fix_ok"]
        ours[name] = {
            "fixes": int(ok.sum()),
            "mean_error_m": float(_errors_m(dd["fix_xy_m"][ok], truth[ok]).mean()) if ok.any() else math.nan,
            "queries_per_s": s["scans"] / s["match_s"] if s["match_s"] > 0 else math.nan,
        }
    same = full["dump"]["fix_ok"]
    agree = _errors_m(full["dump"]["fix_xy_m"][same], pred[same])
    return {
        "measured": (
            f"dense fingerprints over all {d['map_dbm'].shape[1]} map APs, fill {FILL_DBM:.0f} dBm for an AP "
            "missing at an RP or in a scan, on both sides; mean error vs the scan's true position; queries/s "
            "= scans / wall time inside sf_fingerprint_match (C) or predict (sklearn, dense queries prebuilt)"
        ),
        "n_rp": int(d["map_dbm"].shape[0]),
        "n_ap": int(d["map_dbm"].shape[1]),
        "scans": len(truth),
        "sklearn": (
            f"scikit-learn {sklearn.__version__} KNeighborsRegressor(n_neighbors=3, weights='distance'), "
            f"euclidean on dBm, algorithm {knn._fit_method}"  # noqa: SLF001 - names what 'auto' chose
        ),
        "sklearn_mean_error_m": float(err_knn.mean()),
        "sklearn_fixes": len(truth),
        "sklearn_mean_error_m_where_ours_fixed": float(err_knn[same].mean()) if same.any() else math.nan,
        "sklearn_fit_s": fit_s,
        "sklearn_queries_per_s_batch": len(truth) / batch_s,
        "sklearn_queries_per_s_single": len(rows) / single_s,
        "ours": "sf_fingerprint_match WkNN k=3, 1/d weights, fill -100 dBm, map_level 1",
        "ours_preselect": ours["preselect"],
        "ours_full_visit": ours["full_visit"],
        "full_visit_vs_sklearn_max_m": float(agree.max()) if agree.size else math.nan,
        # the C matcher scores only RPs that share a used AP with the scan (its AP-major index),
        # sklearn every RP: a scan hearing few map APs can be "near" an RP of one weak entry it
        # shares nothing with, so the two differ there (a few % of real scans)
        "same_fix_fraction": float(np.mean(agree < 0.01)) if agree.size else math.nan,
    }


def format_rows(att: dict[str, Any], knn: dict[str, Any]) -> list[str]:
    """The console lines of both peers, saying what was measured."""
    return [
        f"  attitude peers, wall time per sample ({att['samples']} samples, median of {REPEATS}, Python): "
        f"ahrs Madgwick MARG {att['madgwick_us_per_sample']:,.1f} us, imufusion Python API "
        f"{att['fusion_python_us_per_sample']:,.1f} us; yaw Madgwick vs Fusion after {SETTLE_S:.0f} s: "
        f"RMS {att['yaw_rms_diff_deg']:.2f} deg, max {att['yaw_max_abs_diff_deg']:.2f} deg"
        + (
            f"; ours vs Fusion: RMS {att['ours_vs_fusion_yaw_rms_deg']:.2f} deg, max "
            f"{att['ours_vs_fusion_yaw_max_abs_deg']:.2f} deg, mean {att['ours_vs_fusion_yaw_mean_deg']:+.2f} deg"
            if "ours_vs_fusion_yaw_rms_deg" in att
            else ""
        ),
        format_knn_row(knn, "the synthetic map"),
    ]


def format_knn_row(knn: dict[str, Any], where: str) -> str:
    """The console line of one KNN peer (:func:`compare_knn`) on ``where``."""
    p, f = knn["ours_preselect"], knn["ours_full_visit"]
    return (
        f"  Wi-Fi peer on {where} ({knn['n_rp']} RPs, {knn['n_ap']} APs, {knn['scans']} scans, dense "
        f"fill {FILL_DBM:.0f} dBm both sides): sklearn KNN k=3 distance-weighted {knn['sklearn_mean_error_m']:.2f} m, "
        f"{knn['sklearn_queries_per_s_batch']:,.0f} q/s batch, {knn['sklearn_queries_per_s_single']:,.0f} q/s one "
        f"by one; ours {p['mean_error_m']:.2f} m {p['queries_per_s']:,.0f} q/s (pre-selection, {p['fixes']} fixes), "
        f"{f['mean_error_m']:.2f} m {f['queries_per_s']:,.0f} q/s (full visit); the same k nearest in "
        f"{knn['same_fix_fraction']:.0%} of the scans"
    )
