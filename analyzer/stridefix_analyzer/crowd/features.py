"""Per-pair fingerprint features for the dissimilarity → distance models, computed blockwise.

On both msindoor floors the thesis's ``common_sum`` (Kannan 2024, Eq. 4; see
:mod:`.model`) degenerates, so the candidates of :mod:`.models` try other features of a scan pair.
Every feature comes from the same matrix products as :func:`.model._block` (V = RSS + 100 dB, 0 where
not heard; M the heard mask; Q = V²), so a block of B_a × B_b pairs costs O(B_a·B_b·m) and memory
O(B_a·B_b):

* n* = M_a·M_bᵀ (APs heard in common), union = c_a + c_b − n* (c = APs heard per scan);
* Σ_C Δ² = Q_a·M_bᵀ + M_a·Q_bᵀ − 2·V_a·V_bᵀ over the common set C (the thesis's sum);
* ``common_sum``    sqrt(Σ_C Δ²)                               [dB]  (thesis Eq. 4, the reference)
* ``common_scaled`` sqrt(Σ_C Δ² · union/n*)                    [dB]  (MATLAB ``naneucdist`` style)
* ``common_rms``    sqrt(Σ_C Δ² / n*)                          [dB]  (the per-AP RSS difference: does
  not grow with the number of APs in common, which ``common_sum`` does — far pairs share few APs, so
  Σ_C Δ² is *smaller* for them and the thesis's line has slope ≈ 0 on real data)
* ``union_rms``     sqrt(Σ_U Δ² / union), a missing AP counted at −100 dBm (V = 0)        [dB]
  = sqrt((Σ_C Δ² + Σ_{U∖C} V²)/union): the RMS difference plus the Jaccard part, the APs heard by
  one scan only, each weighted by how far above the −100 dBm floor it was heard — the "rms +
  λ·jaccard" combination with λ fixed by units (dB above the detection floor) instead of a constant;
* ``jaccard``       1 − n*/union                                [-]   (which APs, not how strong)
* ``cosine``        1 − V_a·V_b / (|V_a|·|V_b|) over all APs (missing = −100 dBm)   [-]

A pair with no AP in common has every feature NaN (the thesis excludes those pairs; keeping them
would change the pair set the models are compared on). Rank (Spearman footrule) features over the
common APs are not offered: they need a per-pair sort and n* is ≤ 3 for most pairs with n* ≥ 1 here.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from stridefix_analyzer.crowd.model import DEFAULT_BLOCK, _block, _Prepared

#: feature name -> (unit, bin width of the streaming fit in that unit)
FEATURES: dict[str, tuple[str, float]] = {
    "common_sum": ("dB", 0.25),
    "common_scaled": ("dB", 0.25),
    "common_rms": ("dB", 0.1),
    "union_rms": ("dB", 0.1),
    "jaccard": ("-", 0.0025),
    "cosine": ("-", 0.0025),
}


def check_feature(name: str) -> None:
    if name not in FEATURES:
        raise ValueError(f"feature {name!r} not one of {tuple(FEATURES)}")


class Prepared(_Prepared):
    """:class:`.model._Prepared` plus the per-scan Σ V² (for the union features)."""

    def __init__(self, R: np.ndarray, dtype=np.float64):
        super().__init__(R, dtype)
        self.q = self.Q.sum(axis=1)


def feature_block(
    pa: Prepared, ia: slice, pb: Prepared, ib: slice, names: tuple[str, ...] | None = None
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Features (dict name -> (b_a, b_b), NaN where no AP in common) and n* of rows ``ia`` × ``ib``."""
    names = tuple(FEATURES) if names is None else names
    for n in names:
        check_feature(n)
    n_common = pa.M[ia] @ pb.M[ib].T
    # Σ_C Δ² through the thesis block (its sqrt, NaN without a common AP), squared back
    d_sum = _block(pa, ia, pb, ib, "common_sum", 1)
    s_common = d_sum * d_sum
    none = n_common < 0.5
    ca = pa.count[ia][:, None].astype(float)
    cb = pb.count[ib][None, :].astype(float)
    union = ca + cb - n_common
    out: dict[str, np.ndarray] = {}
    vv = None
    if "union_rms" in names or "cosine" in names:
        vv = pa.V[ia] @ pb.V[ib].T
    qa, qb = pa.q[ia][:, None], pb.q[ib][None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        for n in names:
            if n == "common_sum":
                f = d_sum
            elif n == "common_scaled":
                f = np.sqrt(s_common * union / n_common)
            elif n == "common_rms":
                f = np.sqrt(s_common / n_common)
            elif n == "union_rms":
                assert vv is not None
                f = np.sqrt(np.maximum(qa + qb - 2.0 * vv, 0.0) / union)
            elif n == "jaccard":
                f = 1.0 - n_common / union
            else:  # cosine
                assert vv is not None
                f = np.clip(1.0 - vv / np.sqrt(qa * qb), 0.0, 1.0)
            f = np.asarray(f, dtype=float)
            f[none] = np.nan
            out[n] = f
    return out, n_common


def features(
    Ra: np.ndarray, Rb: np.ndarray | None = None, names: tuple[str, ...] | None = None
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Features and n* of every scan of ``Ra`` (n_a × m) against every scan of ``Rb`` (default Ra).

    Memory O(n_a·n_b); for many scans use :func:`iter_feature_blocks`.
    """
    pa = Prepared(Ra)
    pb = pa if Rb is None else Prepared(Rb)
    if pa.M.shape[1] != pb.M.shape[1]:
        raise ValueError(f"AP columns differ: {pa.M.shape[1]} vs {pb.M.shape[1]}")
    return feature_block(pa, slice(None), pb, slice(None), names)


def iter_feature_blocks(
    R: np.ndarray, names: tuple[str, ...] | None = None, block: int = DEFAULT_BLOCK
) -> Iterator[tuple[int, int, dict[str, np.ndarray], np.ndarray, np.ndarray]]:
    """Unordered pairs i > j of the scans of ``R`` in blocks, as :func:`.model.iter_pair_blocks`.

    Yields (i0, j0, features, n_common, keep): keep = i > j and at least one AP in common.
    """
    p = Prepared(R)
    n = len(p)
    for i0 in range(0, n, block):
        ia = slice(i0, min(n, i0 + block))
        for j0 in range(0, i0 + 1, block):
            ib = slice(j0, min(n, j0 + block))
            f, nc = feature_block(p, ia, p, ib, names)
            keep = nc > 0.5
            if i0 == j0:
                keep &= np.tri(keep.shape[0], keep.shape[1], -1, dtype=bool)
            yield i0, j0, f, nc, keep


def pair_loop_features(ra: np.ndarray, rb: np.ndarray) -> dict[str, float]:
    """The features of one pair by their definitions (a plain loop; the tests' reference)."""
    ha, hb = np.isfinite(ra), np.isfinite(rb)
    c, u = ha & hb, ha | hb
    nc, nu = int(c.sum()), int(u.sum())
    if nc == 0:
        return {n: math.nan for n in FEATURES}
    dc = ra[c] - rb[c]
    s = float(np.sum(dc * dc))
    va = np.where(ha, ra + 100.0, 0.0)
    vb = np.where(hb, rb + 100.0, 0.0)
    su = float(np.sum((va - vb) ** 2))
    return {
        "common_sum": math.sqrt(s),
        "common_scaled": math.sqrt(s * nu / nc),
        "common_rms": math.sqrt(s / nc),
        "union_rms": math.sqrt(su / nu),
        "jaccard": 1.0 - nc / nu,
        "cosine": 1.0 - float(va @ vb) / math.sqrt(float(va @ va) * float(vb @ vb)),
    }
