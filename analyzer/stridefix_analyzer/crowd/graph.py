"""The crowd graph: every constraint a crowd walk carries, as one GraphSLAM-style least-squares problem.

Kannan (2024) §4 solves positions from anchors and pairwise *ranges*; a range throws away the
direction PDR measures. Here each walk keeps it (Thrun & Montemerlo's GraphSLAM shape: pose nodes,
odometry edges, loop-closure edges, absolute priors), over the points of :func:`.solve.make_points`.

Unknowns: per point k, p_k = (x, y) [m] and θ_k [rad], the walk's heading bias at that point (the
rotation from the dead-reckoning frame to the map; it drifts slowly on a hand-held phone, so it is a
random walk, not one constant); per walk w, its stride scale s_w. Rows (σ in the unit of the row):

* **step** (consecutive points i → j of one walk; d = DR(t_j) − DR(t_i), the dead-reckoned
  displacement in the walk's own frame):  r = ((p_j − p_i) − s_w·R(θ_i)·d) / σ_step,
  σ_step = step_sigma0_m + step_sigma_per_m·‖d‖ (2 residuals);
* **heading** (the same consecutive points): r = (θ_j − θ_i) / (σ_θ·√max(Δt, 0.1 s)) (1 residual);
* **scale** (per walk): r = (s_w − s0) / σ_s;
* **heading prior** (the first point of each walk): r = (θ − θ0) / σ_θ0 (no wrap: the initial θ is
  put within π of θ0). s0, σ_s, θ0, σ_θ0 are the *fleet's* stride scale and heading bias with their
  spread, learned from the anchors alone (:func:`fleet_priors`): a walk with one anchor has no
  heading of its own, and on hand-held phones the bias spreads ±35° between walks, so the prior is
  weak but it is what the crowd knows;
* **anchor** (a known position every K-th truth point: beacon, landmark, surveyed waypoint):
  r = (p_a − q_a) / σ_anchor (2 residuals);
* **range** (Wi-Fi loop closures between points of *different* walks on the same floor, from a
  fitted dissimilarity → distance model with its own spread): r = (b − ‖p_i − p_j‖) / σ_b.

Cost = ½ Σ r² over step, heading, scale and anchor rows + ½ Σ ρ(r²) over range rows, ρ the robust
loss (Ceres's CauchyLoss / HuberLoss with scale ``loss_scale`` in σ units, or none): a fingerprint
that looks like a far place must not pull the walk there. Solved by Ceres (``stridefix_native.
solve_graph``) or its scipy twin (:mod:`.graph_solve`); both minimise exactly this cost.

Initial guess: p from the anchors interpolated in time; θ per walk from the 2-D Procrustes rotation
between the walk's DR and its anchors; s = s0.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np

from stridefix_analyzer.crowd.solve import Points, _initial_guess, parse_anchors
from stridefix_analyzer.crowd.walks import CrowdInputError

LOSSES = ("none", "huber", "cauchy")


@dataclasses.dataclass(frozen=True)
class GraphSettings:
    """Noise of each row kind (module docstring); defaults from walking physics, not from a file.

    σ_θ: a phone held in the hand turns against the walking direction by a few degrees per second of
    wobble and its gyro-integrated heading drifts ~1°/min; 0.05 rad/√s lets the bias move ~17° over a
    2-minute walk between anchors. Steps: ±0.3 m per stride pair of detection jitter plus 10 % of the
    distance for the stride model. Anchors: a surveyed waypoint or a beacon's proximity, ~0.5 m.
    """

    heading_sigma_rad_per_sqrt_s: float = 0.05
    step_sigma0_m: float = 0.3
    step_sigma_per_m: float = 0.1
    anchor_sigma_m: float = 0.5
    loss: str = "cauchy"
    loss_scale: float = 1.0
    #: Wi-Fi rows: at most this many per point (its most similar fingerprints in other walks).
    wifi_per_point: int = 3
    #: Wi-Fi rows only where the model's distance is at most this [m] (near places are what it knows).
    wifi_max_range_m: float = 10.0


DEFAULT_SETTINGS = GraphSettings()


@dataclasses.dataclass(frozen=True)
class FleetPriors:
    """Stride scale and heading bias of the fleet's walks, with their spread (module docstring)."""

    scale: float = 1.0
    scale_sigma: float = 0.3
    heading_rad: float = 0.0
    heading_sigma_rad: float = math.pi
    walks_used: int = 0


#: A walk tells its scale and heading only when its anchors span at least this [m].
MIN_ANCHOR_SPAN_M = 5.0


def walk_similarity(points: Points, is_anchor: np.ndarray, k: int) -> tuple[float, float] | None:
    """(stride scale, heading bias [rad]) of the 2-D similarity that maps walk ``k``'s dead reckoning
    onto its own anchors; None when its anchors span < 5 m (they say nothing). Anchors only."""
    ak = np.flatnonzero((points.walk == k) & is_anchor)
    if len(ak) < 2:
        return None
    A = points.truth_xy_m[ak] - points.truth_xy_m[ak].mean(axis=0)
    B = points.dr_xy_m[ak] - points.dr_xy_m[ak].mean(axis=0)
    span_a, span_b = np.sqrt(np.sum(A * A)), np.sqrt(np.sum(B * B))
    if span_a < MIN_ANCHOR_SPAN_M or span_b < 1e-6:
        return None
    return float(span_a / span_b), _procrustes_heading(points.dr_xy_m[ak], points.truth_xy_m[ak])


def priors_from(similarities: list[tuple[float, float]]) -> FleetPriors:
    """Median and robust spread (1.4826·MAD) of per-walk (scale, heading) pairs
    (:func:`walk_similarity`); the uninformative default below 3 walks."""
    if len(similarities) < 3:
        return FleetPriors(walks_used=len(similarities))
    s, h = (np.asarray(v, float) for v in zip(*similarities))
    h0 = float(np.angle(np.mean(np.exp(1j * h))))  # circular mean, then a robust centre near it
    h = h0 + np.angle(np.exp(1j * (h - h0)))
    h_med = float(np.median(h))
    return FleetPriors(
        scale=float(np.median(s)),
        scale_sigma=max(1.4826 * float(np.median(np.abs(s - np.median(s)))), 0.05),
        heading_rad=h_med,
        heading_sigma_rad=max(1.4826 * float(np.median(np.abs(h - h_med))), math.radians(5.0)),
        walks_used=len(similarities),
    )


def agreed_variant(similarities: Mapping[str, Sequence[tuple[float, float]]]) -> tuple[str, FleetPriors]:
    """Of several dead-reckoning variants of the same walks (variant → the walks' :func:`walk_similarity`),
    the one whose walks agree best on their heading bias (smallest robust spread: a heading the phone
    keeps consistent from walk to walk is one the map's rotation corrects), with its
    :func:`priors_from`. Needs 3 walks that tell; else the first variant, uninformed."""
    best: tuple[str, FleetPriors] | None = None
    for v, sims in similarities.items():
        pri = priors_from(list(sims))
        if pri.walks_used >= 3 and (best is None or pri.heading_sigma_rad < best[1].heading_sigma_rad):
            best = (v, pri)
    return best if best is not None else (next(iter(similarities)), priors_from([]))


def fleet_priors(points: Points, is_anchor: np.ndarray, n_walks: int) -> FleetPriors:
    """:func:`priors_from` the :func:`walk_similarity` of every walk that has one."""
    sims = [walk_similarity(points, is_anchor, k) for k in range(n_walks)]
    return priors_from([v for v in sims if v is not None])


@dataclasses.dataclass
class GraphProblem:
    """The rows of the graph; arrays in the layout of ``stridefix_native.solve_graph``."""

    n_points: int
    n_walks: int
    step_i: np.ndarray  # (k,) int64
    step_j: np.ndarray  # (k,) int64
    step_walk: np.ndarray  # (k,) int64
    step_dxy_m: np.ndarray  # (k, 2) DR displacement in the walk's frame
    step_sigma_m: np.ndarray  # (k,)
    head_i: np.ndarray  # (h,) int64
    head_j: np.ndarray  # (h,) int64
    head_sigma_rad: np.ndarray  # (h,)
    scale_prior: np.ndarray  # (W,)
    scale_sigma: np.ndarray  # (W,)
    hprior_idx: np.ndarray  # (p,) int64
    hprior_rad: np.ndarray  # (p,)
    hprior_sigma_rad: np.ndarray  # (p,)
    anchor_idx: np.ndarray  # (a,) int64
    anchor_xy_m: np.ndarray  # (a, 2)
    anchor_sigma_m: np.ndarray  # (a,)
    pair_i: np.ndarray  # (r,) int64
    pair_j: np.ndarray  # (r,) int64
    range_m: np.ndarray  # (r,)
    range_sigma_m: np.ndarray  # (r,)
    loss: str
    loss_scale: float
    init_xy_m: np.ndarray  # (n, 2)
    init_heading_rad: np.ndarray  # (n,)
    init_scale: np.ndarray  # (W,)

    def rows(self) -> dict[str, int]:
        """How many of each constraint the problem holds (every report row names them)."""
        return {
            "anchors": int(len(self.anchor_idx)),
            "steps": int(len(self.step_i)),
            "heading": int(len(self.head_i)),
            "scale": int(self.n_walks),
            "heading_prior": int(len(self.hprior_idx)),
            "wifi": int(len(self.pair_i)),
        }


def _procrustes_heading(dr: np.ndarray, xy: np.ndarray) -> float:
    """Rotation [rad] that best maps the DR points onto the map points (both centred)."""
    A, B = xy - xy.mean(axis=0), dr - dr.mean(axis=0)
    return float(np.arctan2(np.sum(B[:, 0] * A[:, 1] - B[:, 1] * A[:, 0]), np.sum(B * A)))


def anchor_mask(points: Points, n_walks: int, every: int) -> np.ndarray:
    """Every ``every``-th truth point of each walk (its first included)."""
    is_anchor = np.zeros(len(points.t_us), bool)
    for k in range(n_walks):
        tp = np.flatnonzero((points.walk == k) & points.is_truth)
        is_anchor[tp[::every]] = True
    return is_anchor


def build_graph(
    points: Points,
    n_walks: int,
    *,
    anchors: str | np.ndarray = "every:4",
    settings: GraphSettings = DEFAULT_SETTINGS,
    priors: FleetPriors | None = None,
    wifi_rows: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> GraphProblem:
    """The graph of ``points`` (module docstring).

    ``anchors``: ``every:K`` or a (n,) bool mask of anchored points (their truth is the anchor).
    ``priors``: the fleet's scale and heading (default: learned here by :func:`fleet_priors`).
    ``wifi_rows``: (i, j, range_m, sigma_m) loop closures, e.g. from :func:`.graph_wifi.wifi_rows`.
    """
    if settings.loss not in LOSSES:
        raise CrowdInputError(f"loss {settings.loss!r} not one of {LOSSES}")
    n = len(points.t_us)
    if isinstance(anchors, str):
        is_anchor = anchor_mask(points, n_walks, parse_anchors(anchors))
    else:
        is_anchor = np.asarray(anchors, bool)
    a = np.flatnonzero(is_anchor & np.isfinite(points.truth_xy_m[:, 0]))
    i = np.flatnonzero(points.walk[:-1] == points.walk[1:])
    j = i + 1
    d = points.dr_xy_m[j] - points.dr_xy_m[i]
    dt_s = (points.t_us[j] - points.t_us[i]) * 1e-6
    x0 = _initial_guess(points, is_anchor)
    fp = fleet_priors(points, is_anchor, n_walks) if priors is None else priors
    th0 = np.full(n, fp.heading_rad)
    first = np.zeros(0, np.int64)
    for k in range(n_walks):
        ids = np.flatnonzero(points.walk == k)
        if len(ids) == 0:
            continue
        first = np.append(first, ids[0])
        ak = ids[is_anchor[ids]]
        if len(ak) >= 2:
            h = _procrustes_heading(points.dr_xy_m[ak], points.truth_xy_m[ak])
            th0[ids] = fp.heading_rad + math.remainder(h - fp.heading_rad, 2 * math.pi)
    if wifi_rows is None:
        wi = wj = np.zeros(0, np.int64)
        wb = ws = np.zeros(0)
    else:
        wi, wj, wb, ws = (np.asarray(v) for v in wifi_rows)
    return GraphProblem(
        n_points=n,
        n_walks=n_walks,
        step_i=i.astype(np.int64),
        step_j=j.astype(np.int64),
        step_walk=points.walk[i].astype(np.int64),
        step_dxy_m=np.ascontiguousarray(d, float),
        step_sigma_m=settings.step_sigma0_m + settings.step_sigma_per_m * np.hypot(d[:, 0], d[:, 1]),
        head_i=i.astype(np.int64),
        head_j=j.astype(np.int64),
        head_sigma_rad=settings.heading_sigma_rad_per_sqrt_s * np.sqrt(np.maximum(dt_s, 0.1)),
        scale_prior=np.full(n_walks, fp.scale),
        scale_sigma=np.full(n_walks, fp.scale_sigma),
        hprior_idx=first,
        hprior_rad=np.full(len(first), fp.heading_rad),
        hprior_sigma_rad=np.full(len(first), fp.heading_sigma_rad),
        anchor_idx=a.astype(np.int64),
        anchor_xy_m=np.ascontiguousarray(points.truth_xy_m[a], float),
        anchor_sigma_m=np.full(len(a), settings.anchor_sigma_m),
        pair_i=wi.astype(np.int64),
        pair_j=wj.astype(np.int64),
        range_m=wb.astype(float),
        range_sigma_m=ws.astype(float),
        loss=settings.loss,
        loss_scale=float(settings.loss_scale),
        init_xy_m=x0,
        init_heading_rad=th0,
        init_scale=np.full(n_walks, fp.scale),
    )
