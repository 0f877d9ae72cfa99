"""Gait model: a person walking a route (``route.py``) at a pace, sampled at the IMU rate.

The person and the unit gait shape are in ``gait.py``; survey stops (turn and scan at calibration
points) in ``survey_stops.py``. Around a staircase the person slows down (0.9 × cadence, 0.85 ×
stride); on a flight each step climbs one stair: stride = the tread (0.28 m), cadence
``stairs.cadence_hz`` × the person's scale (1.5 Hz: 0.26 m/s vertical).

Timeline: the route is cut into bouts by the pauses and by the breaks between legs (turn in place,
elevator ride). A bout is a sequence of steps, each with a period T_k (cadence with jitter) and length
L_k (stride with jitter); a bout starts and ends at rest. The last few metres of each bout are
stretched or shrunk together (factor 0.75-1.35) so that the bout covers exactly its planned distance.

Within step k (phase u = (t − t_k) / T_k in [0, 1); a step runs from mid-stance to mid-stance, heel
strike at u ≈ 0.5):

* mean forward speed v̄ goes smoothly (smoothstep, C1) from the knot before the step to the knot after
  it; knots are the mean of the neighbouring steps' L/T, 0 at the ends of a bout; so the distance
  covered in step k is d_k = T_k · (knot_k + knot_k+1) / 2;
* vertical acceleration a_z = A_k · F(u), where F is a fixed periodic gait shape of unit peak-to-peak:
  a smooth stance/swing component (minimum at mid-stance, when the body is highest) plus a sharp
  heel-strike peak just after contact (at u_peak ≈ 0.53, the step event recorded as truth; one
  dominant peak per step). Vertical velocity and displacement are its exact integrals,
  v_z = A_k T_k Z'(u), z = A_k T_k² Z(u) (Z ≤ 0, Z = Z' = 0 at mid-stance, so they are continuous
  across steps). The amplitude follows Weinberg's law: A_k = (ℓ_k / K)⁴ · exp(σ·N(0,1)) with ℓ_k = d_k
  (the first and last step of a bout: at least 0.8 L_k — gait initiation bounces more than the body
  moves) and σ = ``walk.bounce_jitter``; on a flight A_k = ``stairs.bounce_p2p_mps2`` · exp(σ·N);
* inverted pendulum: kinetic and potential energy are exchanged, ½v² + η·g·z ≈ const, so
  v = v̄ · (1 − η·g·(z − z̄_k) / v_k²) with v_k = L_k / T_k, z̄_k the step's mean height and η =
  ``walk.pendulum_recovery`` (real walking recovers ~65 %; on flights η/7): the body is slowest at
  mid-stance when it is highest, and forward acceleration ≈ −η·g·v_z·v̄/v_k² is in antiphase with the
  vertical velocity;
* lateral sway a_y = −sway · cos(π (k + u)) · min(1, v̄ / v_k): half the step rate, towards the stance
  foot, fading in and out with the speed.

Position and heading come from the distance walked along the route; curvature adds centripetal
acceleration v²κ on body y and yaw rate κv. On a flight the walking surface rises with the distance
(slope = riser / tread), adding h''·v² + h'·dv/dt to the vertical acceleration. Between legs the person
stands: turns in place (smoothstep, 90 °/s mean, 135 °/s peak) and, for an elevator, rides: a jerk-limited profile
(acceleration a·sin², up to ``elevator.accel_mps2``, cruise at ``elevator.speed_mps``).

Truth: the floor is the nearest floor level of the walking surface (the upper one at exactly half-way);
activity per sample: still, walking, stairs (steps on a flight) or elevator (while the cab moves).
Body frame: x forward, y left, z up; the body stays level and faces the walking direction. Outputs are
arrays at the IMU rate (no per-sample Python loops).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .gait import (
    G_MPS2,
    GAIT_DZ,
    GAIT_F,
    GAIT_U,
    GAIT_U_PEAK,
    GAIT_Z,
    GAIT_Z_MEAN,
    TURN_RATE_DPS,
    Person,
    make_person,
)
from .route import Route, make_route
from .survey_route import survey_route
from .survey_stops import plan_stop
from .world import World, survey_points

ACTIVITIES = ("still", "walking", "stairs", "elevator")
ACT_STILL, ACT_WALK, ACT_STAIRS, ACT_ELEVATOR = range(4)
MODE_WALK, MODE_SLOW, MODE_STAIRS = 0, 1, 2
STAIRS_PENDULUM_FACTOR = 1.0 / 7.0
SLOW_CADENCE, SLOW_STRIDE = 0.9, 0.85  # around a staircase
TAIL_M = 5.0  # the last metres of a bout absorb the distance correction


@dataclass
class Walk:
    """Ground-truth kinematics at the IMU rate (sample i at t_s = i / rate_hz)."""

    t_s: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    heading_rad: np.ndarray  # unwrapped, CCW from map +x: the body's (= walking) direction
    speed_mps: np.ndarray  # horizontal speed
    yaw_rate_radps: np.ndarray
    accel_body_mps2: np.ndarray  # (N, 3) kinematic acceleration in the (level) body frame, gravity excluded
    height_m: np.ndarray  # body height above its standing height on floor 0 (level + gait bounce)
    level_m: np.ndarray  # walking-surface level under the person [m above floor 0]
    vz_mps: np.ndarray  # vertical velocity of the body
    floor: np.ndarray  # true floor index (int)
    activity: np.ndarray  # ACT_* per sample (int8)
    s_m: np.ndarray  # distance walked (horizontal)
    step_t_s: np.ndarray  # time of each step event (heel-strike peak of the vertical acceleration)
    step_len_m: np.ndarray  # horizontal distance covered during each step
    step_p2p_mps2: np.ndarray  # vertical acceleration peak-to-peak (A_k) of each step
    step_mode: np.ndarray  # MODE_* of each step
    walk_end_s: float  # time the last step ends
    route: Route
    person: Person
    rides: list = field(default_factory=list)  # (t_start, t_end, dz_m, break index) of the elevator rides
    stops: list = field(default_factory=list)  # survey: one dict per calibration point (see plan_walk)
    scan_plan: list = field(default_factory=list)  # survey: (t_ms, stop index, orientation_deg, k) per scan


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x), 6 * x * (1 - x)


def _elevator(t_rel: np.ndarray, dz: float, v_max: float, a_max: float):
    """Jerk-limited ride of ``dz`` metres starting at t_rel = 0: z, v_z, a_z, plus its duration."""
    sgn = 1.0 if dz >= 0 else -1.0
    D = abs(dz)
    v = min(v_max, math.sqrt(D * a_max / 2.0))
    tau = 2.0 * v / a_max  # acceleration phase: a = a_max sin²(π t / τ)
    t_c = (D - v * tau) / v  # cruise
    T = 2 * tau + t_c

    def acc_phase(t):
        t = np.clip(t, 0.0, tau)
        ph = 2 * math.pi * t / tau
        a = a_max * np.sin(math.pi * t / tau) ** 2
        vv = a_max * (t / 2 - tau / (4 * math.pi) * np.sin(ph))
        z = a_max * (t * t / 4 + tau * tau / (8 * math.pi**2) * (np.cos(ph) - 1))
        return z, vv, a

    t = np.asarray(t_rel, float)
    z1, v1, a1 = acc_phase(t)
    z3, v3, a3 = acc_phase(T - t)
    z_acc_end = v * tau / 2
    z = np.where(t <= tau, z1, np.where(t <= tau + t_c, z_acc_end + v * (t - tau), D - z3))
    vz = np.where(t <= tau, v1, np.where(t <= tau + t_c, v, v3))
    az = np.where(t <= tau, a1, np.where(t <= tau + t_c, 0.0, -a3))
    z = np.where(t <= 0, 0.0, np.where(t >= T, D, z))
    vz = np.where((t <= 0) | (t >= T), 0.0, vz)
    az = np.where((t <= 0) | (t >= T), 0.0, az)
    return sgn * z, sgn * vz, sgn * az, T


def _plan_bout(length: float, s0: float, route: Route, person: Person, sc: dict, rng: np.random.Generator):
    """Steps of one bout: lengths L, periods T, modes; planned start positions (relative)."""
    w, st = sc["walk"], sc["stairs"]
    tread = route.tread_m
    L, T, M, pos_at = [], [], [], []
    pos = 0.0
    while True:
        mode = {"walk": MODE_WALK, "slow": MODE_SLOW, "stairs": MODE_STAIRS}[
            route.gait_mode(s0 + min(pos, length))
        ]
        if mode == MODE_STAIRS:
            cad = st["cadence_hz"] * person.cadence_scale
            lk = tread * (1.0 + 0.01 * rng.standard_normal())
        else:
            cad = person.cadence_hz * (SLOW_CADENCE if mode == MODE_SLOW else 1.0)
            lk = (
                person.stride_m
                * (SLOW_STRIDE if mode == MODE_SLOW else 1.0)
                * (1.0 + w["stride_jitter"] * rng.standard_normal())
            )
        tk = float(np.clip((1.0 + w["cadence_jitter"] * rng.standard_normal()) / cad, 0.6 / cad, 1.4 / cad))
        L.append(lk)
        T.append(tk)
        M.append(mode)
        pos_at.append(pos)
        if len(L) == 1:
            pos += 0.5 * lk
            continue
        if len(L) >= 2 and length - (pos + 0.5 * lk) < 0.5 * lk:
            break
        pos += lk
    return np.array(L), np.array(T), np.array(M), np.array(pos_at)


def _knots(v: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], 0.5 * (v[:-1] + v[1:]), [0.0]])


def _bout_distance(v: np.ndarray, T: np.ndarray) -> float:
    kn = _knots(v)
    return float(np.sum(T * (kn[:-1] + kn[1:]) / 2))


def plan_walk(sc: dict, route: Route, person: Person, rng: np.random.Generator) -> dict:
    """The timeline: steps (start, period, knots, length, mode, bout), leg switches, turns and rides."""
    w, el = sc["walk"], sc["elevator"]
    total = route.length_m
    leg_s = route.leg_starts_m
    cuts = {}
    for p in w["pause"] if route.name != "survey" else []:
        if 0 < p["at_m"] < total:
            cuts.setdefault(round(p["at_m"], 9), []).append(("pause", p["duration_s"]))
    for at_m, dur_s in route.pauses:  # the route's own (the legs' waits)
        cuts.setdefault(round(at_m, 9), []).append(("pause", dur_s))
    for i, _br in enumerate(route.breaks):
        cuts.setdefault(round(float(leg_s[i + 1]), 9), []).append(("leg", i))
    bounds = [0.0] + sorted(cuts) + [total]

    # heading at the start/end of each leg (path frame), to plan the turns in place
    hd_start = [float(leg.path.pose(np.array([0.0]))[2][0]) for leg in route.legs]
    hd_end = [float(leg.path.pose(np.array([leg.length_m]))[2][0]) for leg in route.legs]

    t = w["start_still_s"]
    steps = {k: [] for k in ("t0", "T", "v", "mode", "bout", "Lplan", "first", "last")}
    switches, turns, rides, stops, scan_plan = [], [], [], [], []
    if route.start_stop is not None:
        t = plan_stop(sc, route.start_stop, None, hd_start[0], t, 0, turns, stops, scan_plan, t_arrive=0.0)
    for b, (s0, s1) in enumerate(zip(bounds[:-1], bounds[1:])):
        d = s1 - s0
        if d > 0.3 * person.stride_m:
            L, T, M, pos_at = _plan_bout(d, s0, route, person, sc, rng)
            v = L / T
            tail = pos_at >= d - TAIL_M
            tail[-2:] = True
            v0 = np.where(tail, 0.0, v)
            D0 = _bout_distance(v0, T)
            D1 = _bout_distance(v, T)
            c = float(np.clip((d - D0) / max(D1 - D0, 1e-9), 0.75, 1.35))
            v = np.where(tail, c * v, v)
            st = t + np.concatenate([[0.0], np.cumsum(T[:-1])])
            steps["t0"].append(st)
            steps["T"].append(T)
            steps["v"].append(v)
            steps["mode"].append(M)
            steps["bout"].append(np.full(len(L), b))
            steps["Lplan"].append(L)
            first = np.zeros(len(L), bool)
            first[0] = True
            last = np.zeros(len(L), bool)
            last[-1] = True
            steps["first"].append(first)
            steps["last"].append(last)
            t = float(st[-1] + T[-1])
        for kind, arg in cuts.get(round(s1, 9), []) if s1 < total else []:
            if kind == "pause":
                t += arg
                continue
            i = arg
            if route.breaks[i].kind == "survey":
                t = plan_stop(
                    sc, route.breaks[i].stop, hd_end[i], hd_start[i + 1], t, i, turns, stops, scan_plan
                )
                switches.append(t)
                continue
            dpsi = math.atan2(math.sin(hd_start[i + 1] - hd_end[i]), math.cos(hd_start[i + 1] - hd_end[i]))
            if abs(abs(dpsi) - math.pi) < 1e-6:
                dpsi = math.pi
            t_turn = max(1.0, math.degrees(abs(dpsi)) / TURN_RATE_DPS) if abs(dpsi) > 1e-6 else 0.0
            turns.append((t + 0.5, t_turn, dpsi, i))
            t_free = t + 0.5 + t_turn + 0.5
            br = route.breaks[i]
            if br.kind == "elevator" and abs(br.dz_m) > 1e-9:
                t_ride = max(t + el["door_s"], t_free)
                _, _, _, dur = _elevator(np.zeros(1), br.dz_m, el["speed_mps"], el["accel_mps2"])
                rides.append((t_ride, t_ride + dur, br.dz_m, len(switches)))
                t = t_ride + dur + el["exit_s"]
            else:
                t = t_free
            switches.append(t)
    if route.end_stop is not None:
        t = plan_stop(sc, route.end_stop, hd_end[-1], None, t, len(route.legs) - 1, turns, stops, scan_plan)
        stops[-1]["t_leave"] = math.inf
    cat = {k: (np.concatenate(v) if v else np.zeros(0)) for k, v in steps.items()}
    cat["mode"] = cat["mode"].astype(int)
    cat["bout"] = cat["bout"].astype(int)
    cat["first"] = cat["first"].astype(bool)
    cat["last"] = cat["last"].astype(bool)
    # knots per bout
    va, vb = np.zeros(len(cat["v"])), np.zeros(len(cat["v"]))
    for b in np.unique(cat["bout"]):
        m = np.flatnonzero(cat["bout"] == b)
        kn = _knots(cat["v"][m])
        va[m], vb[m] = kn[:-1], kn[1:]
    cat["va"], cat["vb"] = va, vb
    cat["d"] = cat["T"] * (va + vb) / 2
    bout_len = np.diff(np.asarray(bounds))
    start_turns = [
        tr[2]
        for tr in turns
        if tr[3] == 0 and route.start_stop is not None and tr[0] < (stops[0]["t_leave"] if stops else 0.0)
    ]
    return {
        "steps": cat,
        "bout_len": bout_len,
        "walk_end": t,
        "switches": switches,
        "turns": turns,
        "rides": rides,
        "hd_start": hd_start,
        "hd_end": hd_end,
        "stops": stops,
        "scan_plan": scan_plan,
        "hd_offset0": -_fsum_exact(start_turns) if start_turns else 0.0,
    }


def _fsum_exact(values) -> float:
    """Sum in order, starting from the first value (a single value comes back bit for bit)."""
    out = None
    for v in values:
        out = v if out is None else out + v
    return 0.0 if out is None else out


def simulate_walk(
    sc: dict,
    world: World,
    rng: np.random.Generator,
    rate_hz: float = 100.0,
    duration_s: float | None = None,
    person: Person | None = None,
) -> Walk:
    """Simulate the walk of scenario ``sc`` (Scenario.data) in ``world``; ``duration_s`` None = auto."""
    w, el = sc["walk"], sc["elevator"]
    if person is None:
        person = make_person(sc, np.random.default_rng(0))
    v_peak = person.stride_m * person.cadence_hz * 1.3
    radius = min(1.0, max(w["turn_radius_m"], v_peak / math.radians(w["max_yaw_rate_dps"])))
    route = make_walk_route(sc, world, radius)
    plan = plan_walk(sc, route, person, rng)
    stp = plan["steps"]
    t0, T, va, vb, mode = stp["t0"], stp["T"], stp["va"], stp["vb"], stp["mode"]
    nst = len(t0)

    # Weinberg amplitudes (walking) and stair amplitudes
    ell = np.where(stp["first"] | stp["last"], np.maximum(stp["d"], 0.8 * stp["Lplan"]), stp["d"])
    jit = np.exp(w["bounce_jitter"] * rng.standard_normal(nst))
    A = np.where(mode == MODE_STAIRS, sc["stairs"]["bounce_p2p_mps2"], (ell / person.weinberg_k) ** 4) * jit
    vk = np.maximum(stp["v"], 0.2)
    eta = w["pendulum_recovery"] * np.where(mode == MODE_STAIRS, STAIRS_PENDULUM_FACTOR, 1.0)

    walk_end = plan["walk_end"]
    if duration_s is None or duration_s <= 0:
        duration_s = math.ceil((walk_end + w["trailing_still_s"]) * 10.0) / 10.0  # whole 0.1 s
    n = int(round(duration_s * rate_hz)) + 1
    n_full = max(n, int(math.ceil(walk_end * rate_hz)) + 2)
    dt = 1.0 / rate_hz
    t = np.arange(n_full) * dt

    k = np.searchsorted(t0, t, side="right") - 1 if nst else np.full(n_full, -1)
    valid = k >= 0
    kk = np.where(valid, k, 0)
    if nst:
        u = (t - t0[kk]) / T[kk]
        valid &= u < 1.0
    else:
        u = np.zeros_like(t)
    u = np.where(valid, u, 0.0)

    def per_step(a, fill=0.0):
        return np.where(valid, a[kk], fill) if nst else np.full(n_full, fill)

    Tk, Ak, vkk, etak = per_step(T, 1.0), per_step(A), per_step(vk, 1.0), per_step(eta)
    a, b = per_step(va), per_step(vb)
    F = np.interp(u, GAIT_U, GAIT_F)
    Zp = np.interp(u, GAIT_U, GAIT_DZ)
    Z = np.interp(u, GAIT_U, GAIT_Z)
    zb = np.where(valid, Ak * Tk**2 * Z, 0.0)
    vzb = np.where(valid, Ak * Tk * Zp, 0.0)
    azb = np.where(valid, Ak * F, 0.0)
    h, dh = _smoothstep(u)
    dh = dh / Tk
    vbar = a + (b - a) * h
    p = -etak * G_MPS2 * (zb - Ak * Tk**2 * GAIT_Z_MEAN) / vkk**2
    v = np.where(valid, vbar * (1.0 + p), 0.0)
    dv = np.where(valid, (b - a) * dh * (1.0 + p) + vbar * (-etak * G_MPS2 * vzb / vkk**2), 0.0)

    # scale each bout's speeds to cover exactly its planned distance (removes integration residue)
    if nst:
        bout_s = np.where(valid, stp["bout"][kk], -1)
        nb = len(plan["bout_len"])
        covered = np.bincount(bout_s[valid], weights=v[valid] * dt, minlength=nb)
        scale = np.where(covered > 0, plan["bout_len"] / np.maximum(covered, 1e-12), 1.0)
        f = np.where(valid, scale[np.maximum(bout_s, 0)], 1.0)
        v = v * f
        dv = dv * f
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])

    # which leg: switch at the end of each break
    switches = np.asarray(plan["switches"])
    leg = np.searchsorted(switches, t, side="right") if len(switches) else np.zeros(n_full, int)
    leg_s = route.leg_starts_m
    d = s - leg_s[leg]
    x, y, hd, kap = (np.zeros(n_full) for _ in range(4))
    lvl, dlvl, d2lvl = (np.zeros(n_full) for _ in range(3))
    off = plan["hd_offset0"]  # 0 unless a survey stop turns the walker before the first leg
    offsets = []
    turn_sum: dict[int, list] = {}
    for tr in plan["turns"]:
        turn_sum.setdefault(tr[3], []).append(tr[2])
    for i, lg in enumerate(route.legs):
        if i > 0:
            off = (
                plan["hd_end"][i - 1]
                + offsets[-1]
                + _fsum_exact(turn_sum.get(i - 1, []))
                - plan["hd_start"][i]
            )
        offsets.append(off)
        m = slice(*np.searchsorted(leg, [i, i + 1]))  # ``leg`` never decreases: leg i is one run
        if m.start == m.stop:
            continue
        dd = np.clip(d[m], 0.0, lg.length_m)
        x[m], y[m], hd[m], kap[m] = lg.path.pose(dd)
        hd[m] += off
        lvl[m], dlvl[m], d2lvl[m] = lg.height(dd)
    yaw_rate = kap * v
    for ts, dur, dpsi, i in plan["turns"]:
        if route.name == "survey" and dur > 0:
            # hundreds of turns: only the samples from the turn's start to the leg switch
            a = int(np.searchsorted(t, ts))
            b = int(np.searchsorted(t, switches[i])) if i < len(switches) else n_full
            r, dr = _smoothstep((t[a:b] - ts) / dur)
            hd[a:b] += dpsi * r
            yaw_rate[a:b] += dpsi * dr / dur
            continue
        before = t < switches[i] if i < len(switches) else np.ones(n_full, bool)
        if dur > 0:
            r, dr = _smoothstep((t - ts) / dur)
            hd += np.where(before, dpsi * r, 0.0)
            yaw_rate += np.where(before, dpsi * dr / dur, 0.0)
    for st in plan["stops"]:  # survey: exactly at the calibration point while standing there
        m = slice(int(np.searchsorted(t, st["t_arrive"] - 1e-9)), int(np.searchsorted(t, st["t_leave"])))
        x[m], y[m] = st["x_m"], st["y_m"]
    vz_lvl = dlvl * v
    az_lvl = d2lvl * v * v + dlvl * dv
    riding = np.zeros(n_full, bool)
    for ts, te, dz, i in plan["rides"]:
        ez, ev, ea, _ = _elevator(t - ts, dz, el["speed_mps"], el["accel_mps2"])
        before = t < switches[i]
        lvl += np.where(before, ez, 0.0)
        vz_lvl += ev
        az_lvl += ea
        riding |= (t >= ts) & (t < te)

    sign = np.where(kk % 2 == 0, 1.0, -1.0)
    ramp = np.clip(vbar / vkk, 0.0, 1.0)
    ay_sway = np.where(valid, -w["sway_mps2"] * sign * np.cos(math.pi * u) * ramp, 0.0)
    acc = np.stack([dv, v * v * kap + ay_sway, az_lvl + azb], axis=1)

    storey = world.storey_m
    floor = np.clip(np.floor((lvl + 1e-3) / storey + 0.5), 0, world.n_floors - 1).astype(int)
    activity = np.full(n_full, ACT_STILL, dtype=np.int8)
    step_mode = per_step(mode, -1)
    activity[valid & (step_mode != MODE_STAIRS)] = ACT_WALK
    activity[valid & (step_mode == MODE_STAIRS)] = ACT_STAIRS
    activity[riding] = ACT_ELEVATOR

    sl = slice(0, n)
    d_scaled = stp["d"] * (scale[stp["bout"]] if nst else 1.0)
    return Walk(
        t_s=t[sl],
        x_m=x[sl],
        y_m=y[sl],
        heading_rad=hd[sl],
        speed_mps=v[sl],
        yaw_rate_radps=yaw_rate[sl],
        accel_body_mps2=acc[sl],
        height_m=(lvl + zb)[sl],
        level_m=lvl[sl],
        vz_mps=(vz_lvl + vzb)[sl],
        floor=floor[sl],
        activity=activity[sl],
        s_m=s[sl],
        step_t_s=t0 + GAIT_U_PEAK * T,
        step_len_m=d_scaled,
        step_p2p_mps2=A,
        step_mode=mode,
        walk_end_s=walk_end,
        route=route,
        person=person,
        rides=plan["rides"],
        stops=plan["stops"],
        scan_plan=plan["scan_plan"],
    )


def make_walk_route(sc: dict, world: World, radius_m: float) -> Route:
    """The scenario's route: the survey of calibration points when ``survey.enabled``, else ``walk.route``."""
    sv = sc["survey"]
    if sv["enabled"]:
        floors = range(world.n_floors) if sv["floor"] < 0 else [sv["floor"]]
        pts = survey_points(world, sv["spacing_m"], sv["margin_m"], floors, sv["layout"])
        return survey_route(world, pts, sv["spacing_m"], radius_m)
    w = sc["walk"]
    return make_route(world, w["route"], w["laps"], radius_m)
