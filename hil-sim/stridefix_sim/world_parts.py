"""What a world of several buildings adds to ``World`` (world.py): the buildings' outlines, its walk as
legs with stair flights, elevator waits and rides (route ``legs``), and its survey as parts walked in
order (survey_route.py). Worlds without them (office, aadr2015, campus) keep every output as it was.

Outlines (``Outline``): a building's name, its footprint as an axis-aligned rectangle (x0, y0, x1, y1)
in the map frame [m] and its floor indices. The building description (building.py) writes each as a
``[[building]]`` with the rectangle's corners counter-clockwise, and gives each wall segment the floors
of the building that holds it (a world still has one plan for every floor: the radio model counts the
walls crossed in plan view, so a one-floor building's walls on floors it does not have change nothing).

Legs (``LegSpec``): waypoints (x, y) or (x, y, corner radius) on one floor; ``flights`` names the
straight stretches (waypoint i to i + 1) that are stair flights and their rise [m] (the level after a
leg is its floor's level plus the rises); ``waits`` (waypoint index, seconds): standing there, e.g.
waiting at the elevator door for the cab. Between two legs the walker stands in the elevator cab and
rides to the next leg's floor (``LegBreak("elevator")``: the scenario's ``elevator`` door and exit
times, a jerk-limited ride).

Survey parts (``SurveyPart``): the calibration points of one floor inside a rectangle, surveyed as one
part; parts are walked in the order given. Between parts on different floors the surveyor rides the
elevator (as the one-building survey does); between parts on one floor they walk ``via_m`` (e.g. out of
one building's door, along the outdoor path, in through another's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Outline:
    name: str
    rect_m: tuple[float, float, float, float]  # x0, y0, x1, y1 [m]
    floors: tuple[int, ...]

    def corners(self) -> list[tuple[float, float]]:
        """The rectangle's vertices, counter-clockwise from (x0, y0)."""
        x0, y0, x1, y1 = self.rect_m
        return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]

    def holds(self, x_m, y_m, tol_m: float = 1e-6) -> np.ndarray:
        """Boolean array: the points lie inside or on the outline."""
        x0, y0, x1, y1 = self.rect_m
        x, y = np.asarray(x_m, float), np.asarray(y_m, float)
        return (x >= x0 - tol_m) & (x <= x1 + tol_m) & (y >= y0 - tol_m) & (y <= y1 + tol_m)


@dataclass(frozen=True)
class LegSpec:
    points: tuple  # ((x, y) or (x, y, radius_m), ...)
    floor: int
    flights: tuple[tuple[int, float], ...] = ()  # (waypoint i: the flight runs from it to i + 1, rise_m)
    waits: tuple[tuple[int, float], ...] = ()  # (waypoint i, seconds standing there)


@dataclass(frozen=True)
class SurveyPart:
    floor: int
    area_m: tuple[float, float, float, float]  # the part's points: its floor's inside this rectangle
    via_m: tuple[tuple[float, float], ...] = ()  # same floor as the previous part: walked between them


def building_of(outlines, x_m: float, y_m: float) -> Outline | None:
    """The outline that holds the point (the first one), None outdoors."""
    for o in outlines:
        if bool(o.holds(x_m, y_m)):
            return o
    return None
