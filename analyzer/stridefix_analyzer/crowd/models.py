"""Candidate dissimilarity → distance models: (feature, functional form, optional n* strata).

The reference row is the thesis's g(x) = max(X1, X2 + X3·x) (Kannan 2024 §3, fitted exactly as
:func:`.model.fit_binned`: bounded least squares, X1 ∈ [0, min distance], X2 ≤ 0, X3 ≥ 0). The other
forms, for the features of :mod:`.features`:

* ``linear``      d = a + b·x (weighted ordinary least squares);
* ``log``         d = a + b·ln(1 + x/x0), b ≥ 0, x0 > 0 (log-distance path loss read backwards: RSS
  differences grow with the log of the distance, so the distance grows ~exponentially… until the
  room ends; the log form is the concave member that keeps growing);
* ``saturating``  d = C + A·(1 − exp(−x/B)), A ≥ 0, B > 0 (past some dissimilarity the scans say
  only "far": the mean distance levels off at the floor's mean pair distance);
* ``power``       d = a + b·(x/x̄)^p, b ≥ 0, p ∈ [0.2, 5] (x̄ the training mean feature, kept in the
  params): convex as well as concave — on msindoor the log and saturating fits run to their linear
  limit (x0, B → bound), the data ask for a distance that grows faster at large cosine/Jaccard;
* ``isotonic``    the non-decreasing step function of least squares (pool-adjacent-violators,
  ``scipy.optimize.isotonic_regression``) on the bins, interpolated linearly between bin means —
  the most flexible monotone g, the bound the parametric forms are measured against.

Strata (optional): the form is fitted separately for pairs with n* (APs heard in common) in
[1, 3), [3, 6), [6, ∞): a feature's noise falls like 1/sqrt(n*) (per-AP RSS noise ≈ 4–6 dB), so the
same dissimilarity means different distances at different n*. A stratum with fewer than
``MIN_STRATUM_PAIRS`` training pairs uses the pooled fit.

Fitting streams: the pairs are binned per feature and stratum (:class:`.model.PairBins`, count, Σx,
Σd, Σd² per bin, memory O(bins)); each form is fitted by least squares on the bin means weighted by
the counts, and the SSE Σ(s2 − 2·g·s1 + n·g²) is exact given the bin-mean feature. The spread
σ(x) [m] is a linear variance model v(x) = s0 + s1·x fitted (weighted by counts) to the per-bin mean
squared residual, floored at (0.1·RMSE)² so no Wi-Fi row weighs more than 10× the typical one.

Every fitted model implements the ``PairModel`` protocol (``name``, ``min_common_aps``,
``predict(Ra, Rb) -> (distance, σ)``, ``to_json``); :func:`model_from_json` reads any of them back,
including the thesis's :class:`.model.DistanceModel` files of ``crowd fit`` (:class:`ThesisAdapter`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Protocol

import numpy as np
from scipy.optimize import isotonic_regression, least_squares

from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd.blocks import merge_bins
from stridefix_analyzer.crowd.features import FEATURES, check_feature, features

FORMS = ("thesis", "linear", "log", "saturating", "power", "isotonic")
#: lower edges of the n* strata (last open-ended)
STRATA_EDGES = (1, 3, 6)
MIN_STRATUM_PAIRS = 200
_SIGMA_FLOOR_FRACTION = 0.1


class PairModel(Protocol):
    name: str
    min_common_aps: int

    def predict(self, Ra: np.ndarray, Rb: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def to_json(self) -> dict: ...


@dataclasses.dataclass(frozen=True)
class Candidate:
    feature: str
    form: str
    stratified: bool = False

    @property
    def name(self) -> str:
        return f"{self.form}/{self.feature}" + ("@n*" if self.stratified else "")


ALL_CANDIDATES: tuple[Candidate, ...] = tuple(
    Candidate(f, form, s) for s in (False, True) for f in FEATURES for form in FORMS
)
REFERENCE = Candidate("common_sum", "thesis")


# --- bins ----------------------------------------------------------------------------------------


def bin_sse(bins: cm.PairBins, g: np.ndarray) -> float:
    """Σ over the pairs of (d − g)² with g given per used bin (at the bin-mean feature)."""
    u = bins.used()
    n = bins.count[u].astype(float)
    return float(max(np.sum(bins.sum_d2[u] - 2.0 * g * bins.sum_d[u] + n * g * g), 0.0))


def bin_sst(bins: cm.PairBins) -> tuple[float, float]:
    """(Σ (d − mean d)², pair count) of the binned pairs."""
    N = float(bins.count.sum())
    if N == 0:
        return 0.0, 0.0
    return float(bins.sum_d2.sum() - bins.sum_d.sum() ** 2 / N), N


# --- forms ---------------------------------------------------------------------------------------


def form_predict(form: str, params: dict, x: np.ndarray) -> np.ndarray:
    """g(x) [m] of ``form`` with ``params`` (NaN stays NaN)."""
    x = np.asarray(x, dtype=float)
    if form == "thesis":
        return cm.model_distance(x, params["X"])
    if form == "linear":
        g = params["a"] + params["b"] * x
    elif form == "log":
        g = params["a"] + params["b"] * np.log1p(np.maximum(x, 0.0) / params["x0"])
    elif form == "saturating":
        g = params["C"] + params["A"] * -np.expm1(-np.maximum(x, 0.0) / params["B"])
    elif form == "power":
        g = params["a"] + params["b"] * (np.maximum(x, 0.0) / params["xs"]) ** params["p"]
    elif form == "isotonic":
        g = np.interp(x, params["x"], params["y"])
    else:
        raise ValueError(f"form {form!r} not one of {FORMS}")
    return np.where(np.isnan(x), np.nan, g)


def _wline(x, y, w) -> tuple[float, float]:
    W = w.sum()
    mx, my = (w * x).sum() / W, (w * y).sum() / W
    vx = (w * (x - mx) ** 2).sum()
    b = (w * (x - mx) * (y - my)).sum() / vx if vx > 0 else 0.0
    return float(my - b * mx), float(b)


def fit_form(form: str, bins: cm.PairBins) -> dict:
    """Least-squares fit of ``form`` on the bin means weighted by count. Raises ValueError if fewer
    than 2 bins hold pairs."""
    u = bins.used()
    if u.sum() < 2:
        raise ValueError(f"need pairs in at least 2 feature bins, got {int(u.sum())}")
    mx, md, _, cnt = bins.means()
    w = cnt.astype(float)
    if form == "thesis":
        m = cm.fit_binned(bins)
        return {"X": list(m.params)}
    if form == "isotonic":
        y = isotonic_regression(md, weights=w, increasing=True).x
        return {"x": mx.tolist(), "y": np.asarray(y).tolist()}
    a, b = _wline(mx, md, w)
    if form == "linear":
        return {"a": a, "b": b}
    sw = np.sqrt(w)
    xs = float(np.average(mx, weights=w)) or 1.0
    if form == "log":

        def resid(p):
            return sw * (md - (p[0] + p[1] * np.log1p(mx / p[2])))

        p0 = [md.min(), max(np.ptp(md), 1e-3), xs]
        lb, ub = [-np.inf, 0.0, 1e-3 * xs], [np.inf, np.inf, 1e3 * xs]
        keys = ("a", "b", "x0")
    elif form == "saturating":

        def resid(p):
            return sw * (md - (p[2] + p[0] * -np.expm1(-mx / p[1])))

        p0 = [max(np.ptp(md), 1e-3), xs, md.min()]
        lb, ub = [0.0, 1e-3 * xs, -np.inf], [np.inf, 1e3 * xs, np.inf]
        keys = ("A", "B", "C")
    elif form == "power":

        def resid(p):
            return sw * (md - (p[0] + p[1] * (mx / xs) ** p[2]))

        p0 = [md.min(), max(np.ptp(md), 1e-3), 1.0]
        lb, ub = [-np.inf, 0.0, 0.2], [np.inf, np.inf, 5.0]
        keys = ("a", "b", "p")
    else:
        raise ValueError(f"form {form!r} not one of {FORMS}")
    p0 = np.clip(p0, np.add(lb, 1e-12), np.subtract(ub, 1e-12))
    res = least_squares(resid, p0, bounds=(lb, ub), method="trf", x_scale="jac", max_nfev=2000)
    out = dict(zip(keys, (float(v) for v in res.x), strict=True))
    if form == "power":
        out["xs"] = xs
    return out


def fit_sigma(form: str, params: dict, bins: cm.PairBins) -> dict:
    """Linear variance model of the residual (module docstring): {"s0", "s1", "var_floor"} [m², m²/unit]."""
    mx, _, _, cnt = bins.means()
    u = bins.used()
    n = cnt.astype(float)
    g = form_predict(form, params, mx)
    msr = np.maximum(bins.sum_d2[u] / n - 2.0 * g * bins.sum_d[u] / n + g * g, 0.0)
    s0, s1 = _wline(mx, msr, n)
    mse = float(np.sum(msr * n) / n.sum())
    return {"s0": s0, "s1": s1, "var_floor": (_SIGMA_FLOOR_FRACTION**2) * mse}


def sigma_predict(sig: dict, x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    v = np.maximum(sig["s0"] + sig["s1"] * x, sig["var_floor"])
    return np.where(np.isnan(x), np.nan, np.sqrt(v))


# --- fitted models -------------------------------------------------------------------------------


def stratum_of(n_common: np.ndarray, edges: tuple[int, ...] | list[int]) -> np.ndarray:
    """Stratum index (0..len(edges)−1) of each n* (values below edges[0] go to stratum 0)."""
    s = np.searchsorted(np.asarray(edges), np.asarray(n_common) + 0.5, side="right") - 1
    return np.clip(s, 0, len(edges) - 1)


@dataclasses.dataclass
class FittedModel:
    """A fitted candidate: one (params, σ) per stratum (one entry when not stratified)."""

    name: str
    feature: str
    form: str
    params: list[dict]
    sigma: list[dict]
    strata_edges: list[int] = dataclasses.field(default_factory=lambda: [1])
    min_common_aps: int = 1
    fit: dict = dataclasses.field(default_factory=dict)

    def predict_feature(self, x: np.ndarray, n_common: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(distance, σ) [m] for feature values ``x`` of pairs with ``n_common`` APs in common."""
        x = np.asarray(x, dtype=float)
        nc = np.asarray(n_common, dtype=float)
        g = np.full(x.shape, np.nan)
        s = np.full(x.shape, np.nan)
        st = stratum_of(nc, self.strata_edges)
        for k, (p, sg) in enumerate(zip(self.params, self.sigma, strict=True)):
            sel = st == k
            if sel.any():
                g[sel] = form_predict(self.form, p, x[sel])
                s[sel] = sigma_predict(sg, x[sel])
        bad = ~(nc >= max(self.min_common_aps, 1) - 0.5) | ~np.isfinite(x)
        g[bad] = np.nan
        s[bad] = np.nan
        return g, s

    def predict(self, Ra: np.ndarray, Rb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f, nc = features(Ra, Rb, (self.feature,))
        return self.predict_feature(f[self.feature], nc)

    def to_json(self) -> dict:
        d = dataclasses.asdict(self)
        d["kind"] = "stridefix.crowd.models/v1"
        d["feature_unit"] = FEATURES[self.feature][0]
        return d

    @classmethod
    def from_json(cls, doc: dict) -> FittedModel:
        names = {f.name for f in dataclasses.fields(cls)}
        missing = [k for k in ("name", "feature", "form", "params", "sigma") if k not in doc]
        if missing:
            raise ValueError(f"model document lacks {missing}")
        check_feature(doc["feature"])
        if doc["form"] not in FORMS:
            raise ValueError(f"form {doc['form']!r} not one of {FORMS}")
        return cls(**{k: v for k, v in doc.items() if k in names})


def fit_candidate(cand: Candidate, strata_bins: list[cm.PairBins], min_common_aps: int = 1) -> FittedModel:
    """Fit ``cand`` on per-stratum bins (index = stratum of :data:`STRATA_EDGES`) of its feature."""
    width = FEATURES[cand.feature][1]
    pooled = merge_bins(strata_bins, width_db=width)
    p_all = fit_form(cand.form, pooled)
    s_all = fit_sigma(cand.form, p_all, pooled)
    params, sigma, used = [p_all], [s_all], ["pooled"]
    edges = [1]
    if cand.stratified:
        edges = list(STRATA_EDGES)
        params, sigma, used = [], [], []
        for b in strata_bins:
            p, s, how = p_all, s_all, "pooled"
            if b.n_pairs >= MIN_STRATUM_PAIRS and b.used().sum() >= 2:
                p = fit_form(cand.form, b)
                s, how = fit_sigma(cand.form, p, b), "own"
            params.append(p)
            sigma.append(s)
            used.append(how)
    m = FittedModel(cand.name, cand.feature, cand.form, params, sigma, edges, min_common_aps)
    sse = heldout_sse(m, strata_bins)
    sst, N = bin_sst(pooled)
    m.fit = {
        "n_pairs": int(N),
        "rmse_m": math.sqrt(sse / N) if N else math.nan,
        "r2": 1.0 - sse / sst if sst > 0 else math.nan,
        "strata_fit": used,
        "method": f"least squares on {int(pooled.used().sum())} bins of {width:g} {FEATURES[cand.feature][0]}",
    }
    return m


def heldout_sse(m: FittedModel, strata_bins: list[cm.PairBins]) -> float:
    """SSE of ``m`` on the pairs of per-stratum bins (index = stratum of :data:`STRATA_EDGES`): each
    bin predicted at its mean feature, distance sums exact."""
    parts = [merge_bins(strata_bins, width_db=FEATURES[m.feature][1])] if len(m.params) == 1 else strata_bins
    total = 0.0
    for p, b in zip(m.params, parts, strict=True):
        if b.used().any():
            total += bin_sse(b, form_predict(m.form, p, b.means()[0]))
    return total


@dataclasses.dataclass
class ThesisAdapter:
    """A thesis :class:`.model.DistanceModel` (e.g. ``crowd fit``'s model.json) as a ``PairModel``;
    σ = the model's RMSE unless a variance model is given."""

    model: cm.DistanceModel
    sigma: dict | None = None

    @property
    def name(self) -> str:
        return f"thesis/{self.model.mode}"

    @property
    def min_common_aps(self) -> int:
        return int(self.model.min_common_aps)

    def predict(self, Ra: np.ndarray, Rb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = cm.dissimilarity(Ra, Rb, self.model.mode)
        _, nc = features(Ra, Rb, ())
        x[nc < max(self.min_common_aps, 1) - 0.5] = np.nan
        g = self.model(x)
        r = self.model.rmse_m if math.isfinite(self.model.rmse_m) else 1.0
        sig = self.sigma or {"s0": r * r, "s1": 0.0, "var_floor": 0.0}
        return g, sigma_predict(sig, x)

    def to_json(self) -> dict:
        d = self.model.to_json()
        d["kind"] = "stridefix.crowd.model/thesis"
        d["sigma"] = self.sigma
        return d


def model_from_json(doc: dict) -> Any:
    """The ``PairModel`` of a document written by ``to_json`` (either class) or by ``crowd fit``."""
    if "slope_m_per_db" in doc:
        sig = doc.get("sigma")
        return ThesisAdapter(cm.DistanceModel.from_json(doc), sig if isinstance(sig, dict) else None)
    return FittedModel.from_json(doc)


def read_pair_model(path: str) -> Any:
    """The pair model of a file written by ``crowd models`` (its best candidate) or ``crowd fit``."""
    import json  # noqa: PLC0415

    from stridefix_analyzer.crowd.walks import CrowdInputError  # noqa: PLC0415

    try:
        with open(path) as f:
            doc = json.load(f)
        return model_from_json(doc["best"] if isinstance(doc, dict) and "best" in doc else doc)
    except (OSError, ValueError, TypeError, KeyError) as exc:
        raise CrowdInputError(f"{path}: cannot read a pair model ({type(exc).__name__}: {exc})") from exc
