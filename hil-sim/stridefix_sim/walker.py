"""Gait model: a person walking laps of the corridor loop, sampled at the IMU rate.

Route: the corridor centre line, a rectangle whose corners are circular arcs (radius widened when
needed so that yaw rate = speed / radius stays under ``max_yaw_rate_dps``). The walk is split into
bouts by the pauses; each bout is a sequence of steps with a per-step period (cadence with jitter) and
length (stride with jitter). Within step k (duration T_k, phase u = (t - t_k) / T_k in [0, 1)):

* mean forward speed v̄ rises smoothly (smoothstep, zero acceleration at step boundaries) from the speed
  at the step's start to the speed at its end; bouts start and end at rest;
* forward speed  v = v̄ · (1 + surge · sin 2πu)   (braking at heel strike, push-off; cf. Zijlstra &
  Hof 1997, "Displacement of the pelvis during human walking");
* vertical acceleration  a_z = (P_k / 2) · (cos 4πu − cos 2πu): zero at the step boundaries, zero mean,
  one peak of P_k at mid-step (the step event recorded as truth), small secondary bumps of 0 at the
  boundaries — so a peak detector with a threshold ~1 m/s² sees exactly one peak per step;
* lateral sway acceleration  a_y = sway · sin(π (k + u)): half the step rate, alternating sides.

Each bout's speeds are scaled by one factor so that it covers exactly its planned distance; positions
and heading come from the arc length walked. Body frame: x forward, y left, z up; the body stays level
and faces the walking direction. Outputs are arrays at the IMU rate (no per-sample Python loops).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .world import World

G_MPS2 = 9.80665


@dataclass(frozen=True)
class Route:
    """Closed rounded-rectangle route. ``pose(s_m)`` gives x, y, unwrapped heading, curvature."""

    corners_m: np.ndarray  # (4, 2) CCW, bottom-left first
    radius_m: float
    start_s_m: float       # arc length of the start point from the loop origin

    @property
    def x0(self) -> float:
        return float(self.corners_m[0, 0])

    @property
    def y0(self) -> float:
        return float(self.corners_m[0, 1])

    @property
    def x1(self) -> float:
        return float(self.corners_m[2, 0])

    @property
    def y1(self) -> float:
        return float(self.corners_m[2, 1])

    def _segments(self):
        """(length, kind, data): straights ('L', start xy, heading) and arcs ('A', centre xy, start angle)."""
        r = self.radius_m
        x0, y0, x1, y1 = self.x0, self.y0, self.x1, self.y1
        w, h = x1 - x0 - 2 * r, y1 - y0 - 2 * r
        q = 0.5 * math.pi * r
        return [
            (w, "L", (x0 + r, y0), 0.0),
            (q, "A", (x1 - r, y0 + r), -0.5 * math.pi),
            (h, "L", (x1, y0 + r), 0.5 * math.pi),
            (q, "A", (x1 - r, y1 - r), 0.0),
            (w, "L", (x1 - r, y1), math.pi),
            (q, "A", (x0 + r, y1 - r), 0.5 * math.pi),
            (h, "L", (x0, y1 - r), 1.5 * math.pi),
            (q, "A", (x0 + r, y0 + r), math.pi),
        ]

    @property
    def perimeter_m(self) -> float:
        return float(sum(seg[0] for seg in self._segments()))

    def pose(self, s_m: np.ndarray):
        """Pose at arc length ``s_m`` walked from the start: x_m, y_m, heading_rad (unwrapped), curvature_1pm."""
        s_m = np.asarray(s_m, dtype=float)
        P = self.perimeter_m
        s_abs = s_m + self.start_s_m
        lap = np.floor(s_abs / P)
        s_loop = s_abs - lap * P
        x = np.empty_like(s_loop)
        y = np.empty_like(s_loop)
        hd = np.empty_like(s_loop)
        k = np.zeros_like(s_loop)
        r = self.radius_m
        segs = self._segments()
        seg_start = np.cumsum([0.0] + [seg[0] for seg in segs[:-1]])
        idx = np.clip(np.searchsorted(seg_start, s_loop, side="right") - 1, 0, len(segs) - 1)
        for i, (length, kind, (cx, cy), ang) in enumerate(segs):
            m = idx == i
            d = s_loop[m] - seg_start[i]
            if kind == "L":
                x[m] = cx + d * math.cos(ang)
                y[m] = cy + d * math.sin(ang)
                hd[m] = ang
            else:
                phi = ang + d / r
                x[m] = cx + r * np.cos(phi)
                y[m] = cy + r * np.sin(phi)
                hd[m] = phi + 0.5 * math.pi
                k[m] = 1.0 / r
        return x, y, hd + 2 * math.pi * lap, k


def make_route(world: World, radius_m: float) -> Route:
    x0 = float(world.loop_corners_m[0, 0])
    sx, sy = world.start_xy_m
    if abs(sy - world.loop_corners_m[0, 1]) > 1e-9 or not (x0 + radius_m <= sx):
        raise ValueError("the start point must lie on the bottom straight of the loop")
    return Route(corners_m=np.asarray(world.loop_corners_m, float), radius_m=radius_m,
                 start_s_m=sx - (x0 + radius_m))


@dataclass
class Walk:
    """Ground-truth kinematics at the IMU rate (sample i at t_s = i / rate_hz)."""

    t_s: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    heading_rad: np.ndarray      # unwrapped, CCW from map +x
    speed_mps: np.ndarray
    yaw_rate_radps: np.ndarray
    accel_body_mps2: np.ndarray  # (N, 3) kinematic acceleration in the (level) body frame, gravity excluded
    height_m: np.ndarray         # vertical bounce of the body about its standing height
    s_m: np.ndarray              # distance walked
    step_t_s: np.ndarray         # time of each step event (vertical acceleration peak)
    walk_end_s: float            # time of the end of the last step
    route: Route


def _steps(sc: dict, rng: np.random.Generator, route_len_m: float):
    """Plan the steps: arrays of start time, period, boundary speeds, peak, bout id; plus bout lengths."""
    w = sc["walk"]
    cadence = w["cadence_hz"]
    stride = w["speed_mps"] / cadence if w["speed_mps"] > 0 else w["stride_m"]
    cuts = sorted(p["at_m"] for p in w["pause"] if 0 < p["at_m"] < route_len_m)
    pause_s = {p["at_m"]: p["duration_s"] for p in w["pause"]}
    bounds = [0.0] + cuts + [route_len_m]
    t = w["start_still_s"]
    starts, periods, va, vb, peaks, bout_of_step, bout_len = [], [], [], [], [], [], []
    for b, (s0, s1) in enumerate(zip(bounds[:-1], bounds[1:])):
        d = s1 - s0
        bout_len.append(d)
        if d > 0.5 * stride:
            n = max(2, int(round(d / stride)) + 1)
            T = (1.0 / cadence) * (1.0 + w["cadence_jitter"] * rng.standard_normal(n))
            T = np.clip(T, 0.6 / cadence, 1.4 / cadence)
            L = stride * (1.0 + w["stride_jitter"] * rng.standard_normal(n))
            v = L / T
            knots = np.concatenate([[0.0], 0.5 * (v[:-1] + v[1:]), [0.0]])
            P = w["bounce_peak_mps2"] * (1.0 + w["bounce_jitter"] * rng.standard_normal(n))
            P = np.clip(P, 0.5 * w["bounce_peak_mps2"], 1.5 * w["bounce_peak_mps2"])
            P[0] *= 0.8  # first and last step of a bout are softer
            P[-1] *= 0.8
            st = t + np.concatenate([[0.0], np.cumsum(T[:-1])])
            starts.append(st)
            periods.append(T)
            va.append(knots[:-1])
            vb.append(knots[1:])
            peaks.append(P)
            bout_of_step.append(np.full(n, b))
            t = float(st[-1] + T[-1])
        if s1 < route_len_m:
            t += pause_s[s1]
    cat = (lambda a: np.concatenate(a) if a else np.zeros(0))
    return (cat(starts), cat(periods), cat(va), cat(vb), cat(peaks),
            cat(bout_of_step).astype(int), np.asarray(bout_len), t)


def simulate_walk(sc: dict, world: World, rng: np.random.Generator, rate_hz: float = 100.0,
                  duration_s: float | None = None) -> Walk:
    """Simulate the walk of scenario ``sc`` (Scenario.data) in ``world``; ``duration_s`` None = auto."""
    w = sc["walk"]
    cadence = w["cadence_hz"]
    stride = w["speed_mps"] / cadence if w["speed_mps"] > 0 else w["stride_m"]
    v_peak = stride * cadence * (1.0 + w["surge"]) * 1.15
    radius = min(1.0, max(w["turn_radius_m"], v_peak / math.radians(w["max_yaw_rate_dps"])))
    route = make_route(world, radius)
    route_len = w["laps"] * route.perimeter_m

    t0, T, va, vb, P, bout, bout_len, walk_end = _steps(sc, rng, route_len)
    if duration_s is None or duration_s <= 0:
        duration_s = math.ceil((walk_end + w["trailing_still_s"]) * 10.0) / 10.0  # whole 0.1 s
    n = int(round(duration_s * rate_hz)) + 1
    # simulate the whole walk (for the per-bout distance scaling), then cut to the duration
    n_full = max(n, int(math.ceil(walk_end * rate_hz)) + 2)
    dt = 1.0 / rate_hz
    t = np.arange(n_full) * dt

    k = np.searchsorted(t0, t, side="right") - 1
    valid = k >= 0
    kk = np.where(valid, k, 0)
    if len(t0):
        u = (t - t0[kk]) / T[kk]
        valid &= u < 1.0
    else:
        u = np.zeros_like(t)
        valid[:] = False
    u = np.where(valid, u, 0.0)
    Tk = np.where(valid, T[kk] if len(T) else 1.0, 1.0)
    a = np.where(valid, va[kk] if len(va) else 0.0, 0.0)
    b = np.where(valid, vb[kk] if len(vb) else 0.0, 0.0)
    Pk = np.where(valid, P[kk] if len(P) else 0.0, 0.0)

    two_pi_u = 2 * math.pi * u
    h = u * u * (3 - 2 * u)
    dh = 6 * u * (1 - u) / Tk
    vbar = a + (b - a) * h
    surge = w["surge"]
    osc = 1.0 + surge * np.sin(two_pi_u)
    v = np.where(valid, vbar * osc, 0.0)
    dv = np.where(valid, (b - a) * dh * osc + vbar * surge * 2 * math.pi * np.cos(two_pi_u) / Tk, 0.0)

    # scale each bout's speeds to cover exactly its planned distance
    if len(t0):
        bout_s = np.where(valid, bout[kk], -1)
        covered = np.bincount(bout_s[valid], weights=v[valid] * dt, minlength=len(bout_len))
        scale = np.where(covered > 0, bout_len / np.maximum(covered, 1e-12), 1.0)
        f = np.where(valid, scale[np.maximum(bout_s, 0)], 1.0)
        v = v * f
        dv = dv * f
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])

    az = np.where(valid, 0.5 * Pk * (np.cos(2 * two_pi_u) - np.cos(two_pi_u)), 0.0)
    zb = np.where(valid, 0.5 * Pk * Tk ** 2 * ((np.cos(two_pi_u) - 1) / (4 * math.pi ** 2)
                                              - (np.cos(2 * two_pi_u) - 1) / (16 * math.pi ** 2)), 0.0)
    sign = np.where(kk % 2 == 0, 1.0, -1.0)
    ay_sway = np.where(valid, w["sway_mps2"] * sign * np.sin(math.pi * u), 0.0)

    x, y, hd, kap = route.pose(s)
    yaw_rate = kap * v
    acc = np.stack([dv, v * v * kap + ay_sway, az], axis=1)

    sl = slice(0, n)
    return Walk(t_s=t[sl], x_m=x[sl], y_m=y[sl], heading_rad=hd[sl], speed_mps=v[sl],
                yaw_rate_radps=yaw_rate[sl], accel_body_mps2=acc[sl], height_m=zb[sl], s_m=s[sl],
                step_t_s=(t0 + 0.5 * T), walk_end_s=walk_end, route=route)
