"""Survey mode: one reference point per distinct surveyed position per floor.

Static scans whose positions lie within ``static_tol_m`` of a point's first scan belong to that
point; moving scans are not used. ``auto`` mode picks survey when at least
:data:`SURVEY_STATIC_FRACTION` of the placed scans are static and the static positions were scanned
:data:`SURVEY_MIN_REPEATS` times or more on average.
"""

from __future__ import annotations

import math

import numpy as np

#: auto mode: share of placed scans that must be static for a survey
SURVEY_STATIC_FRACTION = 0.8
#: auto mode: mean scans per surveyed position for a survey
SURVEY_MIN_REPEATS = 2.0


def survey_points(x, y, floor, tol_m: float) -> np.ndarray:
    """Cluster index per scan: a scan joins the first point of its floor within tol_m of that
    point's first scan, else starts a new point (points numbered in order of first scan)."""
    ids = np.empty(len(x), dtype=np.int64)
    anchors: list[tuple[int, float, float]] = []
    for k in range(len(x)):
        for j, (f, ax, ay) in enumerate(anchors):
            if f == floor[k] and math.hypot(x[k] - ax, y[k] - ay) <= tol_m:
                ids[k] = j
                break
        else:
            ids[k] = len(anchors)
            anchors.append((int(floor[k]), float(x[k]), float(y[k])))
    return ids
