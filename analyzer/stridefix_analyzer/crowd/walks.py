"""Walks for the crowdsourced model: Wi-Fi scans, truth and steps of one recording each.

A *walk* is one recording on one clock (the argument grouping of ``stridefix radiomap``): an argument
``a.lcmlog,b.lcmlog`` is one walk of those files (e.g. the firmware log and the simulator's truth log,
or the firmware's replay log and the imported msindoor log); a plain argument with WIFI and TRUTH is a
walk by itself; the remaining plain arguments are merged into one walk. When several files of a walk
hold WIFI (a replay log republishes its input's scans) only the first file's scans are used.

Truth: *dense* when the walk has TRUTH of source SIMULATION (the simulator's 10 Hz samples), else the
WAYPOINT rows (surveyed points of a real walk; linear interpolation between them is the usual truth).
A scan's true position is the truth interpolated linearly at the scan time; scans outside the truth's
time span or between samples on different floors have none (NaN).

Dead reckoning from ``STEP`` (``length_m``, ``heading_rad``): DR(t) = Σ over steps with t_step ≤ t of
length·(cos h, sin h) [m], and the path length S(t) = Σ length. The PDR distance of two points of a
walk is the chord ‖DR(t_j) − DR(t_i)‖ (``chord``, default: invariant to the absolute heading, only the
heading change within the span matters) or S(t_j) − S(t_i) (``path``: Σ step lengths between the two
times; equal to the chord on a straight stretch).
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from collections.abc import Sequence

import numpy as np

from stridefix_analyzer.crowd.model import fingerprint_matrix
from stridefix_analyzer.io.lcmfile import require_records
from stridefix_analyzer.io.logread import LogTruncatedWarning, read_logs

SOURCE_SIMULATION, SOURCE_WAYPOINT = 1, 2
BANDS = ("2.4", "all")
DEFAULT_BAND = "2.4"
#: A waypoint point borrows the fingerprint of the nearest scan within this time [s].
DEFAULT_BORROW_S = 2.0


def add_walk_arguments(p) -> None:
    """The arguments every crowd command takes: the walks (``LOG``) and the Wi-Fi band."""
    p.add_argument(
        "logs",
        nargs="+",
        metavar="LOG",
        help="walks: 'a.lcmlog,b.lcmlog' = one walk (firmware log + truth log)",
    )
    p.add_argument(
        "--band",
        choices=BANDS,
        default=DEFAULT_BAND,
        help=f"APs used: 2.4 GHz only as the thesis, or all (default {DEFAULT_BAND})",
    )


class CrowdInputError(Exception):
    """The logs cannot be used (no WIFI, no TRUTH, no STEP where needed). The message says why."""


@dataclasses.dataclass
class Walk:
    """One recording: scans (n,), their AP rows (a,), truth (k,), steps (s,)."""

    name: str
    scan_t_us: np.ndarray
    ap_scan: np.ndarray
    ap_bssid: np.ndarray
    ap_rssi_dbm: np.ndarray
    ap_freq_mhz: np.ndarray
    truth_t_us: np.ndarray
    truth_xy_m: np.ndarray
    truth_floor: np.ndarray
    dense_truth: bool
    step_t_us: np.ndarray
    step_length_m: np.ndarray
    step_heading_rad: np.ndarray
    scan_complete: np.ndarray | None = None

    @property
    def n_scans(self) -> int:
        return len(self.scan_t_us)

    def place(self, t_us: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """True (x, y) [m] (n, 2) and floor (n,) at times ``t_us`` (NaN / −9999 where unknown)."""
        t = np.asarray(t_us, dtype=np.int64)
        tt, xy, fl = self.truth_t_us, self.truth_xy_m, self.truth_floor
        out = np.full((len(t), 2), np.nan)
        floor = np.full(len(t), -9999, dtype=np.int64)
        if len(tt) == 0:
            return out, floor
        a = np.searchsorted(tt, t, side="right") - 1
        inside = (a >= 0) & (t <= tt[-1])
        a_c = np.clip(a, 0, len(tt) - 1)
        b_c = np.clip(a + 1, 0, len(tt) - 1)
        exact = inside & (tt[a_c] == t)
        same_floor = fl[a_c] == fl[b_c]
        ok = inside & (exact | same_floor)
        span = np.maximum(tt[b_c] - tt[a_c], 1)
        w = np.where(exact | (b_c == a_c), 0.0, (t - tt[a_c]) / span)
        p = xy[a_c] + w[:, None] * (xy[b_c] - xy[a_c])
        out[ok] = p[ok]
        floor[ok] = fl[a_c][ok]
        return out, floor

    def dead_reckoning(self, t_us: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """DR position (n, 2) [m] and path length S (n,) [m] at times ``t_us`` (module docstring)."""
        t = np.asarray(t_us, dtype=np.int64)
        L, h = self.step_length_m, self.step_heading_rad
        dx = np.concatenate([[0.0], np.cumsum(L * np.cos(h))])
        dy = np.concatenate([[0.0], np.cumsum(L * np.sin(h))])
        s = np.concatenate([[0.0], np.cumsum(L)])
        k = np.searchsorted(self.step_t_us, t, side="right")
        return np.column_stack([dx[k], dy[k]]), s[k]


def _keep_band(freq_mhz: np.ndarray, band: str) -> np.ndarray:
    if band not in BANDS:
        raise CrowdInputError(f"band {band!r} not one of {BANDS}")
    if band == "all":
        return np.ones(len(freq_mhz), bool)
    return (freq_mhz >= 2400) & (freq_mhz <= 2500)


def _read(path: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        data = read_logs([path], decode=("WIFI", "TRUTH", "STEP"))
    require_records(data.inputs)  # an empty log, or one cut in its first record: nothing valid
    return data


def _make_walk(files: list[str], datas: list) -> Walk:
    name = " + ".join(os.path.basename(f) for f in files)
    wifi_data = next((d for d in datas if d.table("WIFI")), None)
    truths = [d.table("TRUTH") for d in datas if d.table("TRUTH")]
    if wifi_data is None or not truths:
        missing = [w for w, ok in (("WIFI", wifi_data is not None), ("TRUTH", bool(truths))) if not ok]
        raise CrowdInputError(f"{name}: no {' and no '.join(missing)} messages")
    w, ap = wifi_data.table("WIFI"), wifi_data.table("WIFI_AP")
    t_us = np.concatenate([t["t_us"] for t in truths])
    src = np.concatenate([t["source"] for t in truths])
    x = np.concatenate([t["x_m"] for t in truths])
    y = np.concatenate([t["y_m"] for t in truths])
    fl = np.concatenate([t["floor"] for t in truths])
    dense = bool(np.any(src == SOURCE_SIMULATION))
    sel = src == (SOURCE_SIMULATION if dense else SOURCE_WAYPOINT)
    if not sel.any():
        sel = np.ones(len(src), bool)
    order = np.argsort(t_us[sel], kind="stable")
    steps = [d.table("STEP") for d in datas if d.table("STEP")]
    if steps:
        st = np.concatenate([s["t_us"] for s in steps])
        o = np.argsort(st, kind="stable")
        sl = np.concatenate([s["length_m"] for s in steps])[o]
        sh = np.concatenate([s["heading_rad"] for s in steps])[o]
        st = st[o]
    else:
        st, sl, sh = np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
    return Walk(
        name=name,
        scan_t_us=w["t_us"].astype(np.int64),
        ap_scan=ap["scan_row"].astype(np.int64),
        ap_bssid=ap["bssid"].astype(np.int64),
        ap_rssi_dbm=ap["rssi_dbm"].astype(float),
        ap_freq_mhz=ap["freq_mhz"].astype(np.int64),
        truth_t_us=t_us[sel][order].astype(np.int64),
        truth_xy_m=np.column_stack([x[sel][order], y[sel][order]]),
        truth_floor=fl[sel][order].astype(np.int64),
        dense_truth=dense,
        step_t_us=st.astype(np.int64),
        step_length_m=sl.astype(float),
        step_heading_rad=sh.astype(float),
        scan_complete=w["complete"].astype(bool),
    )


def load_walks(args: Sequence[str | tuple[str, ...]]) -> list[Walk]:
    """Group log arguments into walks (module docstring) and read them; a tuple of paths is one walk
    as is (a file name may hold a comma).

    Raises LogReadError (unreadable file) or CrowdInputError (a walk lacks WIFI or TRUTH).
    """
    walks, rest = [], []
    for arg in args:
        files = list(arg) if isinstance(arg, tuple) else [f for f in str(arg).split(",") if f]
        datas = [_read(f) for f in files]
        if len(files) > 1 or (datas[0].table("WIFI") and datas[0].table("TRUTH")):
            walks.append(_make_walk(files, datas))
        else:
            rest.append((files[0], datas[0]))
    if rest:
        walks.append(_make_walk([f for f, _ in rest], [d for _, d in rest]))
    return walks


@dataclasses.dataclass
class ScanSet:
    """The scans of several walks pooled: fingerprint matrix and truth per scan."""

    R: np.ndarray  # (n, m) RSS [dBm], NaN = not heard
    bssids: np.ndarray  # (m,)
    walk: np.ndarray  # (n,) walk index
    t_us: np.ndarray  # (n,)
    xy_m: np.ndarray  # (n, 2) truth at scan time (NaN unknown)
    floor: np.ndarray  # (n,) truth floor (−9999 unknown)
    usable: np.ndarray  # (n,) complete scan with at least one AP of the band


def pool_scans(walks: list[Walk], band: str = DEFAULT_BAND) -> ScanSet:
    """Pool the scans of ``walks``; AP readings outside ``band`` (``2.4``: 2400–2500 MHz) dropped."""
    rows, bss, rss, walk_id, t, xy, fl, comp = [], [], [], [], [], [], [], []
    base = 0
    for k, w in enumerate(walks):
        keep = _keep_band(w.ap_freq_mhz, band)
        rows.append(w.ap_scan[keep] + base)
        bss.append(w.ap_bssid[keep])
        rss.append(w.ap_rssi_dbm[keep])
        walk_id.append(np.full(w.n_scans, k, np.int64))
        t.append(w.scan_t_us)
        p, f = w.place(w.scan_t_us)
        xy.append(p)
        fl.append(f)
        comp.append(w.scan_complete if w.scan_complete is not None else np.ones(w.n_scans, bool))
        base += w.n_scans
    cat = np.concatenate
    R, bssids = fingerprint_matrix(cat(rows), cat(bss), cat(rss), base)
    usable = cat(comp) & np.isfinite(R).any(axis=1)
    return ScanSet(
        R=R, bssids=bssids, walk=cat(walk_id), t_us=cat(t), xy_m=cat(xy), floor=cat(fl), usable=usable
    )
