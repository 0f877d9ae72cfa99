"""ISO/IEC 18305 terms, floor heights and TUM z: numbers known in advance, and evo on our exports."""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.io.sitefile import new_site, write_site
from stridefix_analyzer.io.tum import TumError, write_tum
from stridefix_analyzer.scoring import floor_height, iso18305
from stridefix_analyzer.scoring.analyze import run_analyze
from stridefix_analyzer.scoring.metrics import run_metrics


def _walk(msg, t, x, y, dx, dy, pose_floor, truth_floor, config=None):
    events = [("CONFIG", msg.config(config))] if config else []
    for i, (ti, xi, yi) in enumerate(zip(t, x, y)):
        events.append(("POSE", msg.pose(ti, xi + dx[i], yi + dy[i], floor=int(pose_floor[i]))))
        events.append(("TRUTH", msg.truth(ti, xi, yi, floor=int(truth_floor[i]))))
    return events


def test_terms_of_a_known_error_cloud(msg, write_log, straight_walk):
    """GIVEN errors (dx, dy) = bias (2, −1) m + a ±1 m alternation on x, and the floor wrong on 10 of
    100 samples, THEN accuracy, precision and floor detection are the closed-form values."""
    t, x, y = straight_walk
    n = len(t)
    alt = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    dx, dy = 2.0 + alt, np.full(n, -1.0)
    truth_floor = np.zeros(n, int)
    pose_floor = np.where(np.arange(n) < 10, 1, 0)
    events = _walk(msg, t, x, y, dx, dy, pose_floor, truth_floor, {"floor.height_m": "4.0"})
    data = read_logs([write_log("w.lcmlog", events)])
    heights = floor_height.resolve(data.config)
    s = run_metrics(data, heights=heights).summary()
    iso = s["iso18305"]
    e = np.hypot(dx, dy)  # √10 and √2, alternating
    assert iso["n"] == n
    assert_allclose(iso["accuracy"]["mean_error_m"], (np.sqrt(10) + np.sqrt(2)) / 2, rtol=1e-12)
    assert_allclose(iso["accuracy"]["rms_error_m"], np.sqrt(6.0), rtol=1e-12)
    assert_allclose([iso["accuracy"]["bias_x_m"], iso["accuracy"]["bias_y_m"]], [2.0, -1.0], atol=1e-12)
    assert_allclose(iso["accuracy"]["bias_m"], np.sqrt(5.0), rtol=1e-12)
    assert_allclose(iso["accuracy"]["ce95_m"], np.percentile(e, 95), rtol=1e-12)
    # the spread is the ±1 m alternation only: the bias costs accuracy, not precision
    p = iso["precision"]
    assert_allclose([p["cov_xx_m2"], p["cov_xy_m2"], p["cov_yy_m2"]], [1.0, 0.0, 0.0], atol=1e-12)
    assert_allclose(p["spread_m"], 1.0, rtol=1e-12)
    assert_allclose(p["error_std_m"], (np.sqrt(10) - np.sqrt(2)) / 2, rtol=1e-12)
    assert_allclose(iso["floor_detection_probability"], 0.9, rtol=1e-12)
    assert iso["floor_detection_probability"] == s["floor_hit_rate"]
    # vertical: 10 samples one floor (4 m) too high
    v = iso["vertical"]
    assert_allclose(v["mean_error_m"], 0.4, rtol=1e-12)
    assert_allclose(
        v["mean_3d_error_m"], np.mean(np.sqrt(e**2 + np.where(pose_floor == 1, 16.0, 0.0))), rtol=1e-12
    )
    assert "floor.height_m = 4 m" in v["heights"] and s["floor_heights"] == v["heights"]
    assert "ISO/IEC 18305" in iso18305.format_line(iso, "adaptive")


def test_no_heights_no_vertical_and_no_multi_floor_tum(msg, write_log, straight_walk, tmp_path):
    t, x, y = straight_walk
    n = len(t)
    floors = np.where(np.arange(n) < 50, 0, 1)
    events = _walk(msg, t, x, y, np.zeros(n), np.zeros(n), floors, floors)  # no CONFIG
    data = read_logs([write_log("w.lcmlog", events)])
    heights = floor_height.resolve(data.config)
    assert not heights.known
    m = run_metrics(data, heights=heights)
    assert m.summary()["iso18305"]["vertical"] is None
    with pytest.raises(TumError, match="--site"):
        write_tum(m, tmp_path / "tum")


def test_site_table_heights_and_tum_z(msg, write_log, straight_walk, tmp_path):
    """GIVEN a site whose floors −1, 0, 1 stand at −3.0, 0.5 and 4.0 m, WHEN exported, THEN each TUM
    line's z is its floor's height from the table (floor 2, above the table, continues at the
    CONFIG's 3.5 m)."""
    site = new_site(lowest_floor=-1, floor_height_m=[-3.0, 0.5, 4.0])
    site_path = tmp_path / "s.sfsite"
    write_site(site_path, site)
    t, x, y = straight_walk
    n = len(t)
    truth_floor = np.repeat([-1, 0, 1, 2], n // 4)
    pose_floor = np.roll(truth_floor, 3)
    events = _walk(msg, t, x, y, np.zeros(n), np.zeros(n), pose_floor, truth_floor, {"floor.height_m": "3.5"})
    log = write_log("w.lcmlog", events)
    summary, metrics = run_analyze([str(log)], str(tmp_path / "an"), site=str(site_path))
    assert summary["floor_heights"].startswith(f"site {site_path}")
    paths = write_tum(metrics, tmp_path / "tum")
    z_of = {-1: -3.0, 0: 0.5, 1: 4.0, 2: 7.5}
    truth_z = np.loadtxt(paths["truth"])[:, 3]
    est_z = np.loadtxt(paths[summary["primary_scheme"]])[:, 3]
    assert_allclose(truth_z, [z_of[f] for f in truth_floor], rtol=0, atol=0)
    assert_allclose(est_z, [z_of[f] for f in pose_floor], rtol=0, atol=0)


def test_evo_ape_on_tum_equals_our_3d_error(msg, write_log, straight_walk, tmp_path):
    """evo's APE (translation, no alignment) on our TUM exports of a walk with floor errors is our
    ISO/IEC 18305 mean 3-D error: z carries the floor."""
    evo_metrics = pytest.importorskip("evo.core.metrics")
    from evo.tools import file_interface

    t, x, y = straight_walk
    n = len(t)
    rng = np.random.default_rng(18305)
    truth_floor = np.where(np.arange(n) < 60, 0, 1)
    pose_floor = np.where(rng.random(n) < 0.2, 1 - truth_floor, truth_floor)
    events = _walk(
        msg,
        t,
        x,
        y,
        rng.normal(0, 2, n),
        rng.normal(0, 2, n),
        pose_floor,
        truth_floor,
        {"floor.height_m": "3.5"},
    )
    summary, metrics = run_analyze([str(write_log("w.lcmlog", events))], str(tmp_path / "an"))
    paths = write_tum(metrics, tmp_path / "tum")
    ape = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
    ape.process_data(
        (
            file_interface.read_tum_trajectory_file(paths["truth"]),
            file_interface.read_tum_trajectory_file(paths[summary["primary_scheme"]]),
        )
    )
    iso = summary["iso18305"]
    assert iso["vertical"]["mean_error_m"] > 0.3  # the floor errors are there
    assert_allclose(
        ape.get_statistic(evo_metrics.StatisticsType.mean), iso["vertical"]["mean_3d_error_m"], atol=1e-9
    )
