"""A synthetic crowd fleet: many walkers on a few floors, as :class:`.walks.Walk` objects (no LCM logs).

For the scale bench and tests of the crowd fit and solve; fully vectorised numpy,
so 100 000 scans / 500 walks take seconds.

Radio: the simulator's log-distance model (``hil-sim/stridefix_sim/radio.py``, its constants from
``stridefix_sim.scenario.DEFAULTS["radio"]``) evaluated for all scans × APs at once:

    RSS = P0 − 10·n·log10(max(d, 1 m)) − α·d − FL·|Δfloor| + X_place + X_scan,   reported when ≥ −95 dBm

P0 = EIRP − FSPL(1 m, f) (the simulator's formula, 18 dBm EIRP on channels 1/6/11); n = 2.5;
FL = 15 dB per floor; d the 3-D distance to the AP on its ceiling. The simulator crosses every wall of
its plan per ray (O(walls) per reading); here the plan is not drawn and its walls are taken in
expectation: α = wall loss (5 dB) / wall spacing (``wall_spacing_m``, 8 m) dB per metre.
Shadowing: X_place ~ N(0, σ_place) per (AP, floor, place), spatially correlated (an i.i.d. grid of
``shadow_cell_m`` cells interpolated bilinearly and renormalised to unit variance), plus the simulator's
per-reading X_scan ~ N(0, 2.5 dB); RSS rounded to whole dBm as a receiver reports it.

Walkers: each on one floor, piecewise-straight legs towards random targets at its own speed
(U(1.1, 1.5) m/s, mean ~1.3 m/s); every leg lasts a whole number of waypoint intervals (~10 s), so the
waypoints (the truth points, a surveyed point every interval) hold every corner and linear interpolation
between them is the exact truth. A scan every U(1.5, 2.5) s. Steps every ``step_period_s``: the
dead-reckoned step is the true displacement over the step × the walk's stride scale (N(1, 0.05)),
heading = true heading + the walk's heading bias (a random offset in (−π, π] — the phone's frame —
plus a random walk of ``heading_drift_rad_per_sqrt_s``).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from stridefix_analyzer.crowd.walks import Walk
from stridefix_common.physics import AP_HEIGHT_M
from stridefix_sim.scenario import DEFAULTS

_RADIO = DEFAULTS["radio"]
EIRP_DBM = 18.0
CHANNELS = (1, 6, 11)
STOREY_M = 4.0


@dataclasses.dataclass(frozen=True)
class FleetSpec:
    """What to generate; defaults: a 3-floor 80 m × 50 m office with an AP every ~12 m."""

    n_walks: int = 500
    n_scans: int = 100_000
    n_floors: int = 3
    floor_w_m: float = 80.0
    floor_h_m: float = 50.0
    ap_spacing_m: float = 12.0
    path_loss_exponent: float = float(_RADIO["path_loss_exponent"])
    floor_loss_db: float = float(_RADIO["floor_loss_db"])
    wall_loss_db: float = float(_RADIO["wall_loss_db"])
    wall_spacing_m: float = 8.0
    scan_sigma_db: float = float(_RADIO["shadowing_db"])
    place_sigma_db: float = 4.0
    shadow_cell_m: float = 5.0
    floor_dbm: float = float(_RADIO["floor_dbm"])
    scan_interval_s: tuple[float, float] = (1.5, 2.5)
    waypoint_interval_s: float = 10.0
    step_period_s: float = 0.55
    speed_m_s: tuple[float, float] = (1.1, 1.5)
    stride_scale_sigma: float = 0.05
    heading_drift_rad_per_sqrt_s: float = 0.01
    seed: int = 1


@dataclasses.dataclass
class Fleet:
    """The walks, the APs (m,) and per-walk truth of what the generator drew."""

    walks: list[Walk]
    ap_xy_m: np.ndarray  # (m, 2)
    ap_floor: np.ndarray  # (m,)
    ap_bssid: np.ndarray  # (m,)
    stride_scale: np.ndarray  # (W,)
    walk_floor: np.ndarray  # (W,)
    spec: FleetSpec


def _aps(spec: FleetSpec, rng: np.random.Generator):
    nx = max(1, int(spec.floor_w_m // spec.ap_spacing_m))
    ny = max(1, int(spec.floor_h_m // spec.ap_spacing_m))
    gx = (np.arange(nx) + 0.5) * spec.floor_w_m / nx
    gy = (np.arange(ny) + 0.5) * spec.floor_h_m / ny
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    per = X.size
    xy = np.tile(np.column_stack([X.ravel(), Y.ravel()]), (spec.n_floors, 1))
    xy += rng.uniform(-0.3, 0.3, xy.shape) * spec.ap_spacing_m
    floor = np.repeat(np.arange(spec.n_floors), per)
    bssid = 0x02_00_00_00_00_00 + 16 * np.arange(len(floor), dtype=np.int64)
    chan = np.asarray(CHANNELS)[np.arange(len(floor)) % len(CHANNELS)]
    freq = 2407 + 5 * chan
    p0 = EIRP_DBM - (20.0 * np.log10(freq) - 27.55)
    return xy, floor, bssid, freq.astype(np.int64), p0


def _waypoints(spec: FleetSpec, n_wp: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(W, n_wp, 2) waypoint positions and (W,) speeds: legs of whole intervals towards random targets
    (a leg ends on the segment to its target, so it stays in the floor's rectangle)."""
    W = spec.n_walks
    lo = np.array([0.0, 0.0])
    hi = np.array([spec.floor_w_m, spec.floor_h_m])
    speed = rng.uniform(*spec.speed_m_s, W)
    hop_m = speed * spec.waypoint_interval_s
    p = lo + rng.uniform(0.1, 0.9, (W, 2)) * (hi - lo)
    out = np.empty((W, n_wp, 2))
    out[:, 0] = p
    left = np.zeros(W, np.int64)
    u = np.zeros((W, 2))
    for k in range(1, n_wp):
        new = left == 0
        if new.any():
            tgt = lo + rng.uniform(0.05, 0.95, (int(new.sum()), 2)) * (hi - lo)
            v = tgt - p[new]
            dist = np.hypot(v[:, 0], v[:, 1])
            left[new] = np.maximum(1, np.floor(dist / hop_m[new]).astype(np.int64))
            u[new] = v / np.maximum(dist, 1e-9)[:, None]
        p = p + u * hop_m[:, None]
        left -= 1
        out[:, k] = p
    return out, speed


def _interp(wp: np.ndarray, t_s: np.ndarray, T: float) -> np.ndarray:
    """Positions (n, 2) of one walk's waypoints ``wp`` (k, 2) at times ``t_s`` (waypoint k at k·T)."""
    a = np.clip((t_s // T).astype(np.int64), 0, len(wp) - 2)
    f = (t_s - a * T) / T
    return wp[a] + f[:, None] * (wp[a + 1] - wp[a])


def _shadow_field(spec: FleetSpec, n_ap: int, rng: np.random.Generator):
    c = spec.shadow_cell_m
    gx, gy = int(math.ceil(spec.floor_w_m / c)) + 2, int(math.ceil(spec.floor_h_m / c)) + 2
    return rng.standard_normal((n_ap, spec.n_floors, gx, gy))


def _place_shadow(field: np.ndarray, floor: np.ndarray, xy: np.ndarray, c: float) -> np.ndarray:
    """(n, m) correlated shadowing (unit variance) at scans (n,) on ``floor`` at ``xy``."""
    fx, fy = xy[:, 0] / c, xy[:, 1] / c
    ix, iy = np.floor(fx).astype(np.int64), np.floor(fy).astype(np.int64)
    ix = np.clip(ix, 0, field.shape[2] - 2)
    iy = np.clip(iy, 0, field.shape[3] - 2)
    wx, wy = fx - ix, fy - iy
    w = [(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy]
    corners = [(ix, iy), (ix + 1, iy), (ix, iy + 1), (ix + 1, iy + 1)]
    s = sum(wk[:, None] * field[:, floor, cx, cy].T for wk, (cx, cy) in zip(w, corners))
    norm = np.sqrt(sum(wk * wk for wk in w))
    return s / norm[:, None]


def make_fleet(spec: FleetSpec = FleetSpec()) -> Fleet:
    """Generate the fleet of ``spec`` (module docstring); deterministic for a seed."""
    if spec.n_walks < 1 or spec.n_scans < spec.n_walks:
        raise ValueError(f"need n_walks >= 1 and n_scans >= n_walks, got {spec.n_walks}, {spec.n_scans}")
    rng = np.random.default_rng(spec.seed)
    ap_xy, ap_floor, bssid, freq, p0 = _aps(spec, rng)
    W, T = spec.n_walks, spec.waypoint_interval_s
    per_walk = np.full(W, spec.n_scans // W)
    per_walk[: spec.n_scans % W] += 1
    gaps = rng.uniform(*spec.scan_interval_s, (W, int(per_walk.max())))
    scan_t = 1.0 + np.cumsum(gaps, axis=1) - gaps[:, :1]
    dur_s = scan_t[np.arange(W), per_walk - 1] + 2.0
    n_wp = int(np.ceil(dur_s.max() / T)) + 2
    wp, _speed = _waypoints(spec, n_wp, rng)
    walk_floor = rng.integers(0, spec.n_floors, W)
    scale = 1.0 + spec.stride_scale_sigma * rng.standard_normal(W)
    bias0 = rng.uniform(-math.pi, math.pi, W)
    field = _shadow_field(spec, len(ap_floor), rng)
    alpha = spec.wall_loss_db / spec.wall_spacing_m
    ap_z = ap_floor * STOREY_M + AP_HEIGHT_M
    walks = []
    for w in range(W):
        ts = scan_t[w, : per_walk[w]]
        n_wp_w = int(np.ceil(dur_s[w] / T)) + 1
        wpw = wp[w, :n_wp_w]
        fl = int(walk_floor[w])
        # radio: (scans, APs)
        xy = _interp(wpw, ts, T)
        dz = fl * STOREY_M + 1.1 - ap_z
        d = np.sqrt((xy[:, :1] - ap_xy[:, 0]) ** 2 + (xy[:, 1:] - ap_xy[:, 1]) ** 2 + dz**2)
        rss = p0 - 10.0 * spec.path_loss_exponent * np.log10(np.maximum(d, 1.0)) - alpha * d
        rss -= spec.floor_loss_db * np.abs(ap_floor - fl)
        rss += spec.place_sigma_db * _place_shadow(field, np.full(len(ts), fl), xy, spec.shadow_cell_m)
        rss += spec.scan_sigma_db * rng.standard_normal(rss.shape)
        rss = np.round(rss)
        si, ai = np.nonzero(rss >= spec.floor_dbm)
        # steps: true displacement × stride scale, heading + bias (offset + random walk)
        st = np.arange(0.5, dur_s[w], spec.step_period_s)
        pa = _interp(wpw, st - spec.step_period_s, T)
        pb = _interp(wpw, st, T)
        dv = pb - pa
        drift = np.cumsum(rng.standard_normal(len(st))) * spec.heading_drift_rad_per_sqrt_s
        drift *= math.sqrt(spec.step_period_s)
        walks.append(
            Walk(
                name=f"fleet-{spec.seed}-w{w:04d}",
                scan_t_us=np.round(ts * 1e6).astype(np.int64),
                ap_scan=si.astype(np.int64),
                ap_bssid=bssid[ai],
                ap_rssi_dbm=rss[si, ai],
                ap_freq_mhz=freq[ai],
                truth_t_us=np.round(np.arange(n_wp_w) * T * 1e6).astype(np.int64),
                truth_xy_m=wpw.copy(),
                truth_floor=np.full(n_wp_w, fl, np.int64),
                dense_truth=False,
                step_t_us=np.round(st * 1e6).astype(np.int64),
                step_length_m=scale[w] * np.hypot(dv[:, 0], dv[:, 1]),
                step_heading_rad=np.arctan2(dv[:, 1], dv[:, 0]) + bias0[w] + drift,
                scan_complete=np.ones(len(ts), bool),
            )
        )
    return Fleet(walks, ap_xy, ap_floor, bssid, scale, walk_floor, spec)
