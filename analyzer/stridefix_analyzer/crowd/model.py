"""Fingerprint dissimilarity and the dissimilarity → distance model of Kannan (2024).

Model (``../shared/papers/kannan-2024-crowdsourced-wifi.md`` §2–§3):

* **Dissimilarity** of two Wi-Fi scans, over the set C of access points both heard (Eq. 4):
  ``common_sum``    d = sqrt(Σ_{i∈C} (RSS_i,1 − RSS_i,2)²)                 [dB]   (the thesis formula)
  ``common_scaled`` d = sqrt(Σ_{i∈C} (RSS_i,1 − RSS_i,2)² · n/n*)          [dB]
  with n* = |C| and n = the APs heard by either scan (the union). MATLAB's ``naneucdist`` uses the
  total AP count for n; the union is our choice: it stays local to the two scans, so the scale does
  not depend on how many APs the whole building has. A pair with no common AP has no dissimilarity
  (NaN) and is excluded everywhere; ``min_common`` > 1 (not in the thesis) also excludes pairs
  sharing fewer APs (on real data one shared AP says little; the model file records the choice).
* **Distance model** ``g(d) = max(X1, X2 + X3·d)`` [m] with X1 ∈ [0, min true distance], X2 ≤ 0,
  X3 ≥ 0, fitted by bounded least squares (``scipy.optimize.least_squares``, trust-region reflective)
  started from an ordinary (weighted) line fit clipped into the bounds.
* **Reliability filter** (§4): keep a pair when g(d) ≤ τ·max g over the candidate pairs, τ = 0.45.

Scans are a (scans × APs) matrix of RSS [dBm] with NaN where an AP was not heard. Pair blocks are
computed with matrix products: with V = RSS + 100 (0 where missing), M the heard mask and Q = V²,
Σ_C Δ² = Q_a·M_bᵀ + M_a·Q_bᵀ − 2·V_a·V_bᵀ and n* = M_a·M_bᵀ (offsetting by 100 dB keeps the terms
small; differences are unchanged). Cost per block pair O(B_a·B_b·m); memory O(B_a·B_b), never the
square of the scan count.

Fitting on many pairs uses **exact streaming binning**: for every block of scan pairs the per-bin
(dissimilarity bin of width ``bin_width_db``) pair count and sums of dissimilarity, distance and
distance² are accumulated (``np.bincount``); the fit then runs on the bin means weighted by their
counts. That is the pair-level least-squares problem with each pair's dissimilarity replaced by its
bin's mean dissimilarity; the sums of distance are exact, so the residual SSE, RMSE and R² are exact
up to that replacement.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.optimize import least_squares

MODES = ("common_sum", "common_scaled")
DEFAULT_MODE = "common_sum"
DEFAULT_TAU = 0.45
DEFAULT_BIN_WIDTH_DB = 0.25
DEFAULT_BLOCK = 2048
RSS_OFFSET_DB = 100.0
#: Upper bound of X1 when the smallest true distance is 0 (least_squares needs lb < ub).
_TINY_M = 1e-9


# --- fingerprint matrix -----------------------------------------------------------------------------


def fingerprint_matrix(
    scan_index: np.ndarray,
    bssid: np.ndarray,
    rssi_dbm: np.ndarray,
    n_scans: int,
    bssids: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Scans × APs RSS matrix from per-AP rows.

    Parameters
    ----------
    scan_index : (a,) int
        Row of each AP reading (0..n_scans−1).
    bssid : (a,) int64
    rssi_dbm : (a,) float
    n_scans : int
    bssids : (m,) int64, optional
        Column order; readings of other BSSIDs are dropped. Default: the sorted distinct BSSIDs.

    Returns
    -------
    R : (n_scans, m) float64, RSS [dBm], NaN where the AP was not heard (a BSSID heard twice in one
        scan keeps its strongest reading).
    bssids : (m,) int64
    """
    scan_index = np.asarray(scan_index, dtype=np.int64)
    bssid = np.asarray(bssid, dtype=np.int64)
    rssi = np.asarray(rssi_dbm, dtype=float)
    if bssids is None:
        bssids = np.unique(bssid)
    bssids = np.asarray(bssids, dtype=np.int64)
    col = np.searchsorted(bssids, bssid)
    col = np.clip(col, 0, max(len(bssids) - 1, 0))
    ok = (len(bssids) > 0) & np.isfinite(rssi)
    if len(bssids):
        ok = ok & (bssids[col] == bssid)
    R = np.full((n_scans, len(bssids)), -np.inf)
    np.maximum.at(R, (scan_index[ok], col[ok]), rssi[ok])
    R[np.isneginf(R)] = np.nan
    return R, bssids


class _Prepared:
    """V (offset values, 0 where missing), M (mask), Q = V², per-row AP counts."""

    def __init__(self, R: np.ndarray, dtype=np.float64):
        R = np.asarray(R, dtype=float)
        if R.ndim != 2:
            raise ValueError(f"fingerprint matrix must be 2-D (scans × APs), got shape {R.shape}")
        heard = np.isfinite(R)
        self.M = heard.astype(dtype)
        self.V = np.where(heard, R + RSS_OFFSET_DB, 0.0).astype(dtype)
        self.Q = self.V * self.V
        self.count = heard.sum(axis=1)
        self.left = np.concatenate([self.Q, self.M, self.V], axis=1)
        self.right = np.concatenate([self.M, self.Q, -2.0 * self.V], axis=1)

    def __len__(self):
        return self.M.shape[0]


def _block(pa: _Prepared, ia: slice, pb: _Prepared, ib: slice, mode: str, min_common: int = 1) -> np.ndarray:
    """Dissimilarity of rows ``ia`` of ``pa`` against rows ``ib`` of ``pb``; NaN = fewer than
    ``min_common`` common APs."""
    s = pa.left[ia] @ pb.right[ib].T
    n_common = pa.M[ia] @ pb.M[ib].T
    np.maximum(s, 0.0, out=s)
    if mode == "common_scaled":
        union = pa.count[ia][:, None] + pb.count[ib][None, :] - n_common
        with np.errstate(divide="ignore", invalid="ignore"):
            s *= union / n_common
    d = np.sqrt(s, out=s)
    d[n_common < max(min_common, 1) - 0.5] = np.nan
    return d


def _check_mode(mode: str) -> None:
    if mode not in MODES:
        raise ValueError(f"dissimilarity mode {mode!r} not one of {MODES}")


def dissimilarity(Ra: np.ndarray, Rb: np.ndarray | None = None, mode: str = DEFAULT_MODE) -> np.ndarray:
    """Pairwise dissimilarity [dB] between the scans of ``Ra`` (n_a × m) and ``Rb`` (n_b × m).

    ``Rb`` defaults to ``Ra``. Returns (n_a, n_b) float64; NaN where the two scans share no AP.
    Memory O(n_a·n_b): for many scans use :func:`iter_pair_blocks`.
    """
    _check_mode(mode)
    pa = _Prepared(Ra)
    pb = pa if Rb is None else _Prepared(Rb)
    if pa.M.shape[1] != pb.M.shape[1]:
        raise ValueError(f"AP columns differ: {pa.M.shape[1]} vs {pb.M.shape[1]}")
    return _block(pa, slice(None), pb, slice(None), mode)


def iter_pair_blocks(
    R: np.ndarray, mode: str = DEFAULT_MODE, block: int = DEFAULT_BLOCK, dtype=np.float64, min_common: int = 1
):
    """Unordered pairs i > j of the scans of ``R``, in blocks.

    Yields
    ------
    (i0, j0, D, keep) : row offset, column offset, (b_i, b_j) dissimilarity block for rows
        i0.., columns j0.., and the (b_i, b_j) bool mask of pairs to use (i > j and a common AP).
    """
    _check_mode(mode)
    p = _Prepared(R, dtype=dtype)
    n = len(p)
    for i0 in range(0, n, block):
        ia = slice(i0, min(n, i0 + block))
        for j0 in range(0, i0 + 1, block):
            ib = slice(j0, min(n, j0 + block))
            D = _block(p, ia, p, ib, mode, min_common)
            keep = np.isfinite(D)
            if i0 == j0:
                keep &= np.tri(D.shape[0], D.shape[1], -1, dtype=bool)
            yield i0, j0, D, keep


# --- streaming binning ------------------------------------------------------------------------------


@dataclasses.dataclass
class PairBins:
    """Per dissimilarity bin k (edges k·width … (k+1)·width [dB]): pair count and sums.

    Attributes: ``count`` (K,) int64; ``sum_x`` Σ dissimilarity [dB]; ``sum_d`` Σ distance [m];
    ``sum_d2`` Σ distance² [m²]; ``min_d`` smallest distance of a used pair [m]; ``n_no_common``
    pairs excluded for having no common AP; ``n_pairs`` pairs used.
    """

    width: float = DEFAULT_BIN_WIDTH_DB
    count: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0, np.int64))
    sum_x: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    sum_d: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    sum_d2: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    min_d: float = math.inf
    n_no_common: int = 0
    n_pairs: int = 0

    def add(self, x: np.ndarray, d: np.ndarray, d2: np.ndarray | None = None) -> None:
        """Accumulate pairs of dissimilarity ``x`` [dB] (finite) and distance ``d`` [m]
        (``d2`` = d², when the caller has it)."""
        x = np.asarray(x, dtype=float).ravel()
        d = np.asarray(d, dtype=float).ravel()
        d2 = d * d if d2 is None else np.asarray(d2, dtype=float).ravel()
        if x.size == 0:
            return
        k = (x / self.width).astype(np.int64)
        n = int(k.max()) + 1
        if n > len(self.count):
            pad = n - len(self.count)
            self.count = np.concatenate([self.count, np.zeros(pad, np.int64)])
            self.sum_x, self.sum_d, self.sum_d2 = (
                np.concatenate([a, np.zeros(pad)]) for a in (self.sum_x, self.sum_d, self.sum_d2)
            )
        m = len(self.count)
        self.count += np.bincount(k, minlength=m)
        self.sum_x += np.bincount(k, weights=x, minlength=m)
        self.sum_d += np.bincount(k, weights=d, minlength=m)
        self.sum_d2 += np.bincount(k, weights=d2, minlength=m)
        self.min_d = min(self.min_d, float(d.min()))
        self.n_pairs += int(x.size)

    def used(self) -> np.ndarray:
        return self.count > 0

    def means(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(mean dissimilarity, mean distance, distance std (ddof 0), count) of the non-empty bins."""
        u = self.used()
        n = self.count[u].astype(float)
        mx, md = self.sum_x[u] / n, self.sum_d[u] / n
        sd = np.sqrt(np.maximum(self.sum_d2[u] / n - md * md, 0.0))
        return mx, md, sd, self.count[u]

    def coarsen(self, factor: int) -> "PairBins":
        """The same sums on bins ``factor`` times wider (exact: sums add)."""
        k = np.arange(len(self.count)) // int(factor)
        m = int(k.max()) + 1 if len(k) else 0
        out = PairBins(
            width=self.width * factor, min_d=self.min_d, n_no_common=self.n_no_common, n_pairs=self.n_pairs
        )
        out.count = np.bincount(k, weights=self.count, minlength=m).astype(np.int64)
        out.sum_x, out.sum_d, out.sum_d2 = (
            np.bincount(k, weights=a, minlength=m) for a in (self.sum_x, self.sum_d, self.sum_d2)
        )
        return out


# --- the distance model -----------------------------------------------------------------------------


def model_distance(x, params) -> np.ndarray:
    """g(d) = max(X1, X2 + X3·d) [m] for dissimilarity ``x`` [dB] (NaN stays NaN)."""
    X1, X2, X3 = (float(v) for v in params)
    x = np.asarray(x, dtype=float)
    return np.where(np.isnan(x), np.nan, np.maximum(X1, X2 + X3 * x))


@dataclasses.dataclass
class DistanceModel:
    """Fitted g(d) = max(X1, X2 + X3·d): ``floor_m`` X1, ``intercept_m`` X2, ``slope_m_per_db`` X3."""

    floor_m: float
    intercept_m: float
    slope_m_per_db: float
    mode: str = DEFAULT_MODE
    min_common_aps: int = 1
    rmse_m: float = math.nan
    r2: float = math.nan
    n_pairs: int = 0
    min_distance_m: float = math.nan
    ols_start: tuple = ()
    method: str = ""
    extra: dict = dataclasses.field(default_factory=dict)

    @property
    def params(self) -> tuple[float, float, float]:
        return (self.floor_m, self.intercept_m, self.slope_m_per_db)

    def __call__(self, x) -> np.ndarray:
        return model_distance(x, self.params)

    def to_json(self) -> dict:
        d = dataclasses.asdict(self)
        d["model"] = "g(d) = max(X1, X2 + X3*d)"
        d["X"] = list(self.params)
        return d

    @classmethod
    def from_json(cls, doc: dict) -> "DistanceModel":
        missing = [k for k in ("floor_m", "intercept_m", "slope_m_per_db") if k not in doc]
        if missing:
            raise ValueError(f"model file lacks {missing}")
        names = {f.name for f in dataclasses.fields(cls)}
        kw = {k: v for k, v in doc.items() if k in names}
        kw["ols_start"] = tuple(kw.get("ols_start", ()))
        return cls(**kw)


def fit_distance_model(
    x, d, weight=None, min_distance_m: float | None = None, mode: str = DEFAULT_MODE, sse_extra=None
) -> DistanceModel:
    """Bounded least-squares fit of g to dissimilarities ``x`` [dB] and distances ``d`` [m].

    Minimises Σ w_k (d_k − g(x_k))² with X1 ∈ [0, min_distance_m], X2 ≤ 0, X3 ≥ 0, from the
    weighted ordinary line fit d ≈ a + b·x clipped into the bounds (X1 starts at half its bound).

    Parameters
    ----------
    x, d : (k,) float — pairs, or bin means (then ``weight`` = bin counts).
    weight : (k,) float, optional (default 1).
    min_distance_m : float, optional — upper bound of X1 (default min d).
    sse_extra : callable(params) -> (sse, sst, n), optional — exact statistics (used by the binned
        fit); default: computed from the weighted pairs.
    """
    x = np.asarray(x, dtype=float)
    d = np.asarray(d, dtype=float)
    w = np.ones_like(x) if weight is None else np.asarray(weight, dtype=float)
    ok = np.isfinite(x) & np.isfinite(d) & (w > 0)
    x, d, w = x[ok], d[ok], w[ok]
    if x.size < 2:
        raise ValueError(f"need at least 2 pairs with a dissimilarity to fit, got {x.size}")
    ub1 = float(np.min(d) if min_distance_m is None else min_distance_m)
    ub1 = max(ub1, _TINY_M)
    # ordinary weighted line fit
    W = w.sum()
    mx, md = (w * x).sum() / W, (w * d).sum() / W
    vx = (w * (x - mx) ** 2).sum()
    b = (w * (x - mx) * (d - md)).sum() / vx if vx > 0 else 0.0
    a = md - b * mx
    x0 = np.array([0.5 * ub1, min(a, 0.0), max(b, 1e-6)])
    sw = np.sqrt(w)

    def resid(X):
        return sw * (d - np.maximum(X[0], X[1] + X[2] * x))

    res = least_squares(
        resid,
        x0,
        bounds=([0.0, -np.inf, 0.0], [ub1, 0.0, np.inf]),
        method="trf",
        x_scale="jac",
        max_nfev=2000,
    )
    X = res.x
    if sse_extra is not None:
        sse, sst, n = sse_extra(X)
    else:
        r = d - np.maximum(X[0], X[1] + X[2] * x)
        sse = float((w * r * r).sum())
        sst = float((w * (d - md) ** 2).sum())
        n = float(W)
    return DistanceModel(
        floor_m=float(X[0]),
        intercept_m=float(X[1]),
        slope_m_per_db=float(X[2]),
        mode=mode,
        rmse_m=math.sqrt(sse / n),
        r2=1.0 - sse / sst if sst > 0 else math.nan,
        n_pairs=int(round(n)),
        min_distance_m=ub1,
        ols_start=(float(a), float(b)),
        method="bounded least squares on pairs",
    )


def fit_binned(bins: PairBins, mode: str = DEFAULT_MODE) -> DistanceModel:
    """Fit on :class:`PairBins` (bin means weighted by counts); exact SSE/SST from the bin sums."""
    u = bins.used()
    if u.sum() < 2:
        raise ValueError(f"need pairs in at least 2 dissimilarity bins, got {int(u.sum())}")
    n = bins.count[u].astype(float)
    mx, md = bins.sum_x[u] / n, bins.sum_d[u] / n
    s1, s2 = bins.sum_d[u], bins.sum_d2[u]
    N = n.sum()
    sst = float(s2.sum() - s1.sum() ** 2 / N)

    def stats(X):
        g = np.maximum(X[0], X[1] + X[2] * mx)
        sse = float(np.sum(s2 - 2 * g * s1 + n * g * g))
        return max(sse, 0.0), sst, N

    m = fit_distance_model(mx, md, n, bins.min_d, mode, sse_extra=stats)
    m.method = (
        f"exact streaming binning: {bins.n_pairs} pairs in {int(u.sum())} dissimilarity "
        f"bins of {bins.width:g} dB (count, Σ distance, Σ distance² per bin); weighted "
        f"bounded least squares on the bin means"
    )
    m.extra = {"n_pairs_no_common_ap": int(bins.n_no_common), "bin_width_db": bins.width}
    return m


# --- reliability filter -----------------------------------------------------------------------------


def reliability_mask(model_dist_m: np.ndarray, tau: float = DEFAULT_TAU) -> tuple[np.ndarray, float]:
    """Pairs kept by the filter: g(d) ≤ τ · max g (NaN never kept). Returns (mask, threshold [m])."""
    g = np.asarray(model_dist_m, dtype=float)
    if not 0 < tau <= 1:
        raise ValueError(f"tau {tau} must be in (0, 1]")
    finite = np.isfinite(g)
    if not finite.any():
        return np.zeros(g.shape, bool), math.nan
    thr = tau * float(np.max(g[finite]))
    with np.errstate(invalid="ignore"):
        return finite & (g <= thr), thr
