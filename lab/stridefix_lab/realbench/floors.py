"""Floors of a fold's site: which floors the training walks visit and how high each one is.

Floor heights (gsd): least squares over the other walks that visit two floors or more, of
``height(walk, floor) = H(floor) + offset(walk)`` with each walk's median barometric height per truth
floor (:func:`floor_heights_of_walk`); floors without such evidence (or no multi-floor walk at all)
get :data:`DEFAULT_STOREY_M` per storey from the nearest known one. The source is reported
(``floor_heights_source``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from stridefix_analyzer.radiomap.build import DEFAULT_FLOOR_HEIGHT_M

#: storey height when the other walks do not give one [m]
DEFAULT_STOREY_M = 4.0


def pressure_to_height_m(pressure_pa: ArrayLike) -> np.ndarray:
    """Barometric height [m], the firmware's formula (sf_floor_pressure_to_height_m)."""
    return 44330.77 * (1.0 - (np.asarray(pressure_pa, float) / 101325.0) ** 0.190263)


def floor_heights_of_walk(
    baro_t_us: ArrayLike,
    pressure_pa: ArrayLike,
    truth_t_us: ArrayLike,
    truth_floor: ArrayLike,
    window_s: float = 2.0,
) -> dict[int, float]:
    """Median barometric height [m] per truth floor: baro samples within ``window_s`` of each truth
    sample, pooled per floor."""
    baro_t_us, truth_t_us = np.asarray(baro_t_us, np.int64), np.asarray(truth_t_us, np.int64)
    if not len(baro_t_us) or not len(truth_t_us):
        return {}
    h = pressure_to_height_m(pressure_pa)
    per: dict[int, list] = {}
    w = int(window_s * 1e6)
    for t, f in zip(truth_t_us, np.asarray(truth_floor, np.int64)):
        i0, i1 = np.searchsorted(baro_t_us, [t - w, t + w])
        if i1 > i0:
            per.setdefault(int(f), []).append(h[i0:i1])
    return {f: float(np.median(np.concatenate(v))) for f, v in per.items()}


def learn_floor_heights(
    per_walk: Sequence[Mapping[int, float]], floors: Sequence[int], storey_m: float = DEFAULT_STOREY_M
) -> tuple[list[float], str]:
    """Heights [m] of ``floors`` (consecutive, ascending) from per-walk floor heights.

    Least squares of h(w, f) = H(f) + c_w over walks that saw two floors or more, H(lowest known) = 0;
    floors without evidence: ``storey_m`` per storey from the nearest known floor. Returns
    (heights, source) where source is ``"barometer"``, ``"barometer+default"`` or ``"default"``.
    """
    multi = [w for w in per_walk if len(w) >= 2]
    known: dict[int, float] = {}
    if multi:
        fl = sorted({f for w in multi for f in w})
        idx = {f: i for i, f in enumerate(fl)}
        rows, rhs = [], []
        nf, nw = len(fl), len(multi)
        for j, w in enumerate(multi):
            for f, h in w.items():
                r = np.zeros(nf + nw)
                r[idx[f]], r[nf + j] = 1.0, 1.0
                rows.append(r)
                rhs.append(h)
        r = np.zeros(nf + nw)
        r[0] = 1.0
        rows.append(r)
        rhs.append(0.0)
        sol = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
        # only floors connected to floor fl[0] through multi-floor walks are meaningful; with one
        # or two multi-floor walks sharing floors that holds; check monotony below anyway
        known = {f: float(sol[idx[f]]) for f in fl}
    heights, used_default = [], False
    for f in floors:
        if f in known:
            heights.append(known[f])
        elif known:
            near = min(known, key=lambda k: abs(k - f))
            heights.append(known[near] + (f - near) * storey_m)
            used_default = True
        else:
            heights.append(f * storey_m)
            used_default = True
    if any(not b > a for a, b in zip(heights, heights[1:])):
        return [f * storey_m for f in floors], "default (barometer heights not increasing)"
    src = "default" if not known else ("barometer+default" if used_default else "barometer")
    return heights, src


def fold_floors(
    others: Sequence[Mapping[str, Any]], own_floors: Sequence[int]
) -> tuple[list[float], str, int]:
    """Floor heights [m], their source and the lowest floor for a site learned from ``others``
    (the floors they visit, or ``own_floors`` when they carry none)."""
    floors = sorted({f for w in others for f in w["floors"]}) or sorted(own_floors)
    fl = list(range(floors[0], floors[-1] + 1))
    if len(fl) > 1:
        heights, src = learn_floor_heights([w["floor_heights"] for w in others], fl)
    else:
        # a one-floor site: the radio map's default storey height (only the index matters)
        heights, src = [fl[0] * DEFAULT_FLOOR_HEIGHT_M], "single floor"
    return heights, src, fl[0]
