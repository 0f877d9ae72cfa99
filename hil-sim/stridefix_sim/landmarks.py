"""Landmark events: the board reads the NFC tag at a door (``Door.landmark_id`` ≠ 0) when it passes
within ``landmark.radius_m`` (0.5 m) of the tag on the tag's floor: one event per pass (a run of walker
samples within the radius), at the sample of closest approach, carrying the tag's surveyed position
and floor (what the tag stores). The board sends the LANDMARK frame ``landmark.latency_ms`` later
(board.py); t_lo_ms is the board time of the read. Cost O(samples × tags).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .walker import Walk
from .world import World


@dataclass
class LandmarkEvent:
    t_ms: int  # read time since the simulation start
    landmark_id: int
    x_m: float
    y_m: float
    floor: int
    distance_m: float  # closest approach of the board to the tag


def simulate_landmarks(sc: dict, world: World, walk: Walk) -> list[LandmarkEvent]:
    lm = sc["landmark"]
    if not lm["enabled"] or len(walk.t_s) < 2:
        return []
    events = []
    for door in world.doors:
        if door.landmark_id == 0:
            continue
        d = np.hypot(walk.x_m - door.x_m, walk.y_m - door.y_m)
        near = (d <= lm["radius_m"]) & (walk.floor == door.floor)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], near.astype(np.int8), [0]])))
        for a, b in zip(edges[::2], edges[1::2]):
            k = a + int(np.argmin(d[a:b]))
            events.append(
                LandmarkEvent(
                    t_ms=int(round(walk.t_s[k] * 1000.0)),
                    landmark_id=door.landmark_id,
                    x_m=door.x_m,
                    y_m=door.y_m,
                    floor=door.floor,
                    distance_m=float(d[k]),
                )
            )
    events.sort(key=lambda e: (e.t_ms, e.landmark_id))
    return events
