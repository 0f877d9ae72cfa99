"""GNSS fixes: what a receiver on the board reports, through the world's geo-reference (``World.geo``).

A fix every ``gnss.period_ms`` (1 Hz) from a random phase. The horizontal error is a first-order
Gauss–Markov process per axis (east, north), and the altitude error another one:

    e_k = φ · e_{k−1} + sqrt(1 − φ²) · σ · w_k,   φ = exp(−Δt / τ),   w_k ~ N(0, 1),   e_0 ~ N(0, σ²)

(σ = ``gnss.sigma_m``, τ = ``gnss.tau_s``; stationary std σ, autocorrelation exp(−lag/τ)), running at
every epoch whether or not a fix is reported. Where a fix is reported:

* outdoors (outside ``World.footprint_m``): always, error e_k, accuracy ≈ σ;
* indoors within ``gnss.door_range_m`` of a door to the outside: with probability
  ``gnss.door_fix_prob``, error ``door_sigma_factor`` · e_k, accuracy ≈ that factor · σ (degraded);
* elsewhere indoors: none.

The reported accuracy (1σ per horizontal axis, the receiver's honest estimate) is the effective σ ×
exp(``gnss.accuracy_jitter`` · N(0, 1)). The fix position is the truth at the fix time (walker sample
nearest it, board at sensor height) plus the error, turned into WGS-84 latitude/longitude by
``GeoRef`` (map → east-north → tangent plane); altitude = origin altitude + walking-surface level +
sensor height + the altitude error. The board sends GNSS_INFO then GNSS_POSITION ``gnss.latency_ms``
after the fix time (board.py). Cost O(fixes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .walker import Walk
from .world import World
from .world_sources import inside

MODE_OUTDOOR, MODE_DOOR = 1, 2


@dataclass
class Fixes:
    """Reported fixes, in time order. t_ms: fix time since the simulation start; lat/lon [deg], alt [m],
    accuracy [m]; x/y: the fix in the map frame [m]; truth_x/truth_y: where the board was; mode MODE_*."""

    t_ms: np.ndarray
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    alt_m: np.ndarray
    accuracy_m: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    truth_x_m: np.ndarray
    truth_y_m: np.ndarray
    mode: np.ndarray

    def __len__(self) -> int:
        return len(self.t_ms)


def gauss_markov(n: int, dt_s: float, sigma: float, tau_s: float, rng: np.random.Generator) -> np.ndarray:
    """(n,) samples of a stationary first-order Gauss–Markov process (std ``sigma``, time constant ``tau_s``)."""
    phi = math.exp(-dt_s / tau_s)
    w = rng.standard_normal(n)
    e = np.empty(n)
    if n == 0:
        return e
    e[0] = sigma * w[0]
    q = sigma * math.sqrt(1.0 - phi * phi)
    for k in range(1, n):  # (a recursion: 1 Hz fixes, a few thousand per hour)
        e[k] = phi * e[k - 1] + q * w[k]
    return e


def _empty() -> Fixes:
    z = np.zeros(0)
    return Fixes(np.zeros(0, np.int64), z, z, z, z, z, z, z, z, np.zeros(0, np.int64))


def simulate_gnss(sc: dict, world: World, walk: Walk, rng: np.random.Generator) -> Fixes:
    g = sc["gnss"]
    if world.geo is None or world.footprint_m is None or not g["enabled"] or len(walk.t_s) < 2:
        return _empty()
    duration_ms = int(round(walk.t_s[-1] * 1000.0))
    dt_ms = int(round((walk.t_s[1] - walk.t_s[0]) * 1000.0))
    period = int(g["period_ms"])
    t_ms = int(rng.integers(0, period)) + period * np.arange(
        max(0, duration_ms // period + 1), dtype=np.int64
    )
    t_ms = t_ms[t_ms + int(g["latency_ms"]) <= duration_ms]
    n, dt_s = len(t_ms), period / 1000.0
    e_e = gauss_markov(n, dt_s, g["sigma_m"], g["tau_s"], rng)
    e_n = gauss_markov(n, dt_s, g["sigma_m"], g["tau_s"], rng)
    e_alt = gauss_markov(n, dt_s, g["sigma_alt_m"], g["tau_s"], rng)
    jitter = np.exp(g["accuracy_jitter"] * rng.standard_normal(n))
    draw = rng.random(n)
    i = np.minimum(np.round(t_ms / dt_ms).astype(int), len(walk.t_s) - 1)
    x, y, fl = walk.x_m[i], walk.y_m[i], walk.floor[i]
    outdoor = ~inside(world.footprint_m, x, y)
    near = np.zeros(n, bool)
    for d in world.doors:
        near |= (np.hypot(x - d.x_m, y - d.y_m) <= g["door_range_m"]) & (fl == d.floor)
    door = ~outdoor & near & (draw < g["door_fix_prob"])
    keep = outdoor | door
    factor = np.where(door, g["door_sigma_factor"], 1.0)
    geo = world.geo
    te, tn = geo.map_to_en(x, y)
    fe, fn = te + factor * e_e, tn + factor * e_n
    lat, lon = geo.en_to_latlon(fe, fn)
    fx, fy = geo.en_to_map(fe, fn)
    alt = geo.origin_alt_m + walk.level_m[i] + sc["baro"]["sensor_height_m"] + factor * e_alt
    acc = g["sigma_m"] * factor * jitter
    mode = np.where(door, MODE_DOOR, MODE_OUTDOOR)
    k = keep
    return Fixes(t_ms[k], lat[k], lon[k], alt[k], acc[k], fx[k], fy[k], x[k], y[k], mode[k])
