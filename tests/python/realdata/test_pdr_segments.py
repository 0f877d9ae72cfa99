"""realbench.pdr_segments: per-segment heading error, distance ratio and steps while standing, on a
walk made by hand whose answers are known."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_lab.realbench.pdr_segments import format_table, segment_table, walk_summary


@pytest.fixture
def l_walk() -> dict[str, np.ndarray]:
    """10 m east in 10 s, a 20 s pause at the corner, 10 m north in 10 s; steps of 0.45 m every 0.5 s
    (0.9 of the truth distance) heading 5° left of the truth; 3 steps before the first waypoint
    (a walker fidgeting at the start) and 4 during the pause."""
    err = math.radians(5.0)
    t1 = np.arange(1, 21) * 500_000  # 20 steps on segment 0: 9 m
    t_pause = 10_000_000 + np.array([2, 5, 9, 14]) * 1_000_000
    t2 = 30_000_000 + np.arange(1, 21) * 500_000
    t_pre = np.array([-3, -2, -1]) * 1_000_000
    t = np.concatenate([t_pre, t1, t_pause, t2])
    h = np.concatenate([np.full(3, 1.0), np.full(20, err), np.full(4, 2.0), np.full(20, math.pi / 2 + err)])
    ln = np.full(len(t), 0.45)
    wp_t = np.array([0, 10_000_000, 30_000_000, 40_000_000])
    wp_xy = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    return {"t": t, "h": h, "l": ln, "wp_t": wp_t, "wp_xy": wp_xy}


def test_segments_heading_error_and_distance_ratio(l_walk: dict[str, np.ndarray]) -> None:
    w = l_walk
    seg = segment_table(w["t"], w["h"], w["l"], w["wp_t"], w["wp_xy"])
    assert seg["straight"].tolist() == [True, False, True]
    assert_allclose(np.degrees(seg["heading_err_rad"][[0, 2]]), [5.0, 5.0], atol=1e-9)
    assert_allclose(seg["dist_ratio"][[0, 2]], [0.9, 0.9], rtol=1e-12)
    assert seg["n_steps"].tolist() == [20, 4, 20]
    assert math.isnan(seg["heading_err_rad"][1])


def test_summary_counts_pause_and_pre_walk_steps(l_walk: dict[str, np.ndarray]) -> None:
    w = l_walk
    seg = segment_table(w["t"], w["h"], w["l"], w["wp_t"], w["wp_xy"])
    s = walk_summary(seg, w["t"], w["h"], w["l"], w["wp_t"])
    assert s["still_steps"] == 4  # the corner pause: 0 m in 20 s
    assert s["pre_walk_steps"] == 3
    assert_allclose(s["pre_walk_m"], 3 * 0.45, rtol=1e-12)  # all three the same way
    assert_allclose([s["heading_err_median_deg"], s["heading_err_mean_deg"]], [5.0, 5.0], atol=1e-9)
    assert_allclose(s["dist_ratio_total"], 0.9, rtol=1e-12)
    assert s["steps"] == 44
    text = format_table([{"walk": "l", "pdr_mean_m": 1.0, **s}])
    assert text.splitlines()[1].startswith("l ")
