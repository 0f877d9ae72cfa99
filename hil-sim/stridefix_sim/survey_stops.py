"""Survey stops: at each calibration point the surveyor turns through the orientations and scans.

The turn-in-place and scan timeline of one stop (see :func:`plan_stop`); ``walker.plan_walk`` calls it
at the route's start, between legs and at its end when the scenario is a survey.
"""

from __future__ import annotations

import math

from .gait import TURN_RATE_DPS
from .route import SurveyStop

SURVEY_TURN_LEAD_S = 0.2  # survey: standing before a turn in place starts
SURVEY_TURN_MIN_S = 0.8  # survey: shortest turn in place
SURVEY_AFTER_SCAN_S = 0.2  # survey: standing after the last scan's results before turning on


def plan_stop(
    sc: dict,
    stop: SurveyStop,
    arrive: float | None,
    depart: float | None,
    t: float,
    leg: int,
    turns: list,
    stops: list,
    scan_plan: list,
    t_arrive: float | None = None,
) -> float:
    """A survey stop from time ``t`` (standing at the point, facing ``arrive``; None = the start): turn in
    place to each of the ``survey.orientations`` headings k·360°/n (map frame; first the one nearest the
    arrival heading, then round in the direction that ends nearest the next leg's heading), take
    ``scans_per_orientation`` scans in each (``settle_s`` after the turn, then every ``scan_interval_s``),
    finally turn to ``depart`` (None = the end). Appends turns (t0, duration, dpsi, leg), the stop and its
    scans; returns the time the surveyor walks on."""
    sv = sc["survey"]
    n = int(sv["orientations"])
    o = [2.0 * math.pi * k / n for k in range(n)]

    def wrap(a):
        a = math.atan2(math.sin(a), math.cos(a))
        return math.pi if abs(abs(a) - math.pi) < 1e-9 else a

    def nearest(h):
        return min(range(n), key=lambda k: (round(abs(wrap(o[k] - h)), 9), k))

    if arrive is None:
        i0, step = (nearest(depart) + 1) % n, 1  # round CCW, ending at the departure heading
    else:
        i0 = nearest(arrive)
        step = 1
        if depart is not None and n > 2:
            ccw, cw = o[(i0 - 1) % n], o[(i0 + 1) % n]
            step = -1 if abs(wrap(depart - cw)) < abs(wrap(depart - ccw)) - 1e-9 else 1
    seq = [o[(i0 + step * k) % n] for k in range(n)]
    cur = seq[0] if arrive is None else arrive
    t_arr = t if t_arrive is None else t_arrive

    def turn(dpsi: float, t: float) -> float:
        if abs(dpsi) < 1e-9:
            return t
        dur = max(SURVEY_TURN_MIN_S, math.degrees(abs(dpsi)) / TURN_RATE_DPS)
        turns.append((t + SURVEY_TURN_LEAD_S, dur, dpsi, leg))
        return t + SURVEY_TURN_LEAD_S + dur

    scan_s = sc["radio"]["scan_duration_ms"] / 1000.0
    for h in seq:
        t = turn(wrap(h - cur), t)
        cur = h
        for k in range(int(sv["scans_per_orientation"])):
            t_ms = int(math.ceil((t + sv["settle_s"] + k * sv["scan_interval_s"]) * 1000.0 - 1e-6))
            scan_plan.append((t_ms, stop.index, round(math.degrees(h) % 360.0, 6), k))
        t = t_ms / 1000.0 + scan_s + SURVEY_AFTER_SCAN_S
    if depart is not None:
        t = turn(wrap(depart - cur), t)
    stops.append(
        {
            "index": stop.index,
            "x_m": stop.x_m,
            "y_m": stop.y_m,
            "floor": stop.floor,
            "t_arrive": t_arr,
            "t_leave": t,
            "orientations_deg": [round(math.degrees(h) % 360.0, 6) for h in seq],
        }
    )
    return t
