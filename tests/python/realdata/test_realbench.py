"""The real-data PDR distance benchmark: calibration on synthetic segments, and a small real run."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.radiomap import strides
from stridefix_lab.realbench import pdr_distance as rb

# --- calibration and segments on synthetic data ---------------------------------------------------


@pytest.fixture
def three_walks():
    """Segments of three walks whose true K differ: 0.3, 0.4, 0.5 (true = K · weinberg)."""
    walk = np.array([0, 0, 1, 1, 1, 2])
    weinberg = np.array([10.0, 20.0, 10.0, 10.0, 20.0, 40.0])
    true_k = np.array([0.3, 0.4, 0.5])[walk]
    return walk, true_k * weinberg, weinberg


def test_lowo_k_uses_only_the_other_walks(three_walks):
    walk, true_m, weinberg = three_walks
    k = strides.calibrate_lowo(walk, true_m, weinberg)
    # K_0 from walks 1, 2: (0.4·40 + 0.5·40) / 80 = 0.45; K_1: (0.3·30 + 0.5·40) / 70; K_2: ...
    assert_allclose(k, [0.45, (9 + 20) / 70, (9 + 16) / 70], rtol=1e-12)


def test_lowo_k_is_blind_to_the_scored_walk(three_walks):
    walk, true_m, weinberg = three_walks
    k = strides.calibrate_lowo(walk, true_m, weinberg)
    changed = true_m.copy()
    changed[walk == 0] *= 5.0
    k2 = strides.calibrate_lowo(walk, changed, weinberg)
    assert k2[0] == k[0]
    assert k2[1] != k[1] and k2[2] != k[2]


def test_lowo_single_walk_has_no_k():
    assert math.isnan(strides.calibrate_lowo([0, 0], [3.0, 4.0], [8.0, 9.0])[0])


def test_lowo_stride_is_median_of_other_walks():
    walk = np.array([0, 1, 1, 1, 2])
    true_m = np.array([100.0, 6.0, 7.0, 8.0, 9.0])
    n_steps = np.array([1, 10, 10, 10, 10])
    # strides: walk 0: 100; walk 1: 0.6, 0.7, 0.8; walk 2: 0.9
    assert_allclose(strides.stride_lowo(walk, true_m, n_steps), [0.75, (100 + 0.9) / 2, 0.75])


def _walk(waypoints, step_t_s, ranges, imu_s=(0.0, 100.0)):
    wp = np.asarray(waypoints, float)
    return {
        "walk": "w",
        "trace": "w.txt",
        "error": None,
        "warnings": [],
        "import": {
            "waypoints": len(wp),
            "imu_t_first_us": int(imu_s[0] * 1e6),
            "imu_t_last_us": int(imu_s[1] * 1e6),
        },
        "waypoint_t_us": (wp[:, 0] * 1e6).astype(np.int64),
        "waypoint_xy_m": wp[:, 1:],
        "step_t_us": (np.asarray(step_t_s) * 1e6).astype(np.int64),
        "step_range_mps2": np.asarray(ranges, float),
        "step_length_m": np.full(len(step_t_s), 0.7),
    }


def test_segments_take_steps_after_start_up_to_end():
    # waypoints at 0 s (0,0), 10 s (6,8) = 10 m, 12 s (7,8) = 1 m (short), 200 s (7,20): no IMU
    walk = _walk(
        [(0, 0, 0), (10, 6, 8), (12, 7, 8), (200, 7, 20)], [0.0, 5.0, 10.0, 11.0], [16.0, 81.0, 1.0, 16.0]
    )
    seg = strides.build_segments([walk], min_segment_m=3.0)
    assert seg["true_m"].tolist() == pytest.approx([10.0, 1.0, 12.0])
    # t0 < t <= t1: the step at 0 s is not in segment 0, the one at 10 s is
    assert seg["n_steps"].tolist() == [2, 1, 0]
    assert seg["weinberg"][0] == pytest.approx(3.0 + 1.0)  # 81^¼ + 1^¼
    assert seg["excluded"].tolist() == ["", "shorter than 3 m", "not covered by IMU data"]


def test_score_segments_end_to_end_synthetic():
    # two walks, both K = 0.5 exactly: LOWO recovers it, errors vanish
    walks = [
        _walk([(0, 0, 0), (10, 10, 0)], np.arange(1, 11), np.full(10, 16.0)),
        _walk([(0, 0, 0), (10, 0, 5)], np.arange(1, 6), np.full(5, 16.0)),
    ]
    seg, fits = rb.score_segments(strides.build_segments(walks), 2)
    assert_allclose(fits["K"], [0.5, 0.5])
    assert_allclose(seg["err_pct"], [0.0, 0.0], atol=1e-9)
    assert_allclose(seg["stride_m"], [1.0, 1.0])


# --- a small real run through the built stridefixd ------------------------------------------------


def test_realbench_small_run(realbench_small):
    proc, out = realbench_small["proc"], realbench_small["out"]
    doc = json.loads((out / rb.JSON_FILE).read_text())
    # exit 0 when the distance target is met, 1 with a TARGET MISSED line when not (4 walks: either)
    assert proc.returncode == (0 if doc["target"]["met"] else 1), proc.stderr
    assert ("TARGET MISSED: realbench pdr-distance" in proc.stdout) == (not doc["target"]["met"])
    assert "walk 4/4" in proc.stderr
    assert "median" in proc.stdout and "K over folds" in proc.stdout
    assert (out / rb.PNG_FILE).stat().st_size > 10_000
    assert doc["walks"]["n"] == 4 and doc["walks"]["ran"] == 4
    # every consecutive waypoint pair is a segment, scored or excluded with a reason
    n_pairs = sum(w["waypoints"] - 1 for w in doc["per_walk"])
    segs = doc["segments"]
    assert segs["n"] == n_pairs == len(doc["segment_rows"])
    assert segs["scored"] + sum(segs["excluded"].values()) == segs["n"]
    assert segs["scored"] >= 10
    for key in ("weinberg_lowo", "baseline_fixed_stride_lowo", "firmware_length_as_configured"):
        e = doc[key]["abs_error_pct"]
        assert e["n"] == segs["scored"]
        assert all(math.isfinite(e[c]) for c in ("mean", "median", "p75", "p90", "max"))
    k = doc["weinberg_lowo"]["K"]
    assert k["n"] == doc["walks"]["scored"]
    assert 0.2 <= k["min"] <= k["max"] <= 1.0
    for row in doc["segment_rows"]:
        if row["excluded"] == "":
            assert math.isfinite(row["err_pct"]) and row["true_m"] >= 3.0
    # K_i really excludes walk i: recompute from the rows of the other walks
    rows = [r for r in doc["segment_rows"] if r["excluded"] == ""]
    for w in doc["per_walk"]:
        if w["segments_scored"]:
            other = [r for r in rows if r["walk"] != w["walk"]]
            expect = sum(r["true_m"] for r in other) / sum(r["weinberg"] for r in other)
            assert w["K"] == pytest.approx(expect, rel=1e-12)


def test_realbench_reuses_cached_imports(realbench_small, cli, stridefixd, lab):
    out = realbench_small["out"]
    before = {p.name: p.stat().st_mtime_ns for p in (out / "cache").glob("*.lcmlog")}
    assert len(before) == 4
    proc = lab(
        "realbench",
        "pdr-distance",
        "--floor",
        str(realbench_small["floor"]),
        "--limit",
        "2",
        "--stridefixd",
        str(stridefixd),
        "--out",
        str(out),
    )
    assert proc.returncode in (0, 1), proc.stderr  # 1: the 2-walk run misses the distance target
    assert "wrote" in proc.stdout
    after = {p.name: p.stat().st_mtime_ns for p in (out / "cache").glob("*.lcmlog")}
    assert after == before


def test_realbench_missing_floor_is_usage_error(cli, tmp_path, lab):
    proc = lab("realbench", "pdr-distance", "--floor", str(tmp_path / "nowhere"))
    assert proc.returncode == 2
    assert "nowhere: no such directory" in proc.stderr


def test_missed_pdr_distance_target_is_named():
    doc = {
        "floor": "site9/F1",
        "target": {"median_abs_error_pct_max": 5.0, "met": False},
        "weinberg_lowo": {"abs_error_pct": {"median": 7.25}},
    }
    (line,) = rb.missed_targets(doc)
    assert "site9/F1" in line and "7.25 %" in line and "target <= 5 %" in line
    doc["target"]["met"] = True
    assert rb.missed_targets(doc) == []
