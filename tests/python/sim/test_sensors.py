"""Sensor imperfections: magnetic disturbance zones, gyro bias random walk and scale error."""

from __future__ import annotations

import math

import numpy as np
import pytest
from stridefix_sim.pipeline import simulate
from stridefix_sim.scenario import builtin_scenario


def test_magnetometer_field_is_perturbed_inside_zones_only(default_result):
    r, _ = default_result
    s, mag = r.sensors, r.scenario["mag"]
    field = s.mag_ut - np.asarray(mag["hard_iron_ut"])
    norm = np.linalg.norm(field, axis=1)
    clean = s.mag_zone_w == 0
    core = s.mag_zone_w > 0.5
    assert clean.mean() > 0.7 and core.sum() > 200
    assert np.all(np.abs(norm[clean] - mag["field_ut"]) < 5 * mag["noise_ut"])
    assert np.abs(norm[core] - mag["field_ut"]).mean() > 5.0
    # dip: the body is level and the board unrotated, so board z is up; undisturbed dip = 60°
    dip = np.degrees(np.arctan2(-field[:, 2], np.hypot(field[:, 0], field[:, 1])))
    assert np.abs(dip[clean] - mag["dip_deg"]).max() < 2.0
    assert np.abs(dip[core] - mag["dip_deg"]).mean() > 3.0
    # every zone is visited on the tour
    x, y, f = (a[s.mag_idx] for a in (r.walk.x_m, r.walk.y_m, r.walk.floor))
    for z in r.world.mag_zones:
        assert (z.weight(x, y, f) > 0.3).any(), z.name


def test_disturbance_scale_zero_leaves_the_field_clean():
    sc = builtin_scenario("pace_normal").with_overrides(**{"duration_s": 40.0, "mag.disturbance_scale": 0.0})
    r = simulate(sc)
    norm = np.linalg.norm(r.sensors.mag_ut - np.asarray(sc["mag"]["hard_iron_ut"]), axis=1)
    assert np.all(np.abs(norm - sc["mag"]["field_ut"]) < 5 * sc["mag"]["noise_ut"])


@pytest.fixture(scope="module")
def drifting_gyro_run():
    """GIVEN a walk with a strongly drifting gyro bias (0.02 °/s/√s) and a 2 % z scale error."""
    sc = builtin_scenario("pace_normal").with_overrides(
        **{
            "duration_s": 120.0,
            "seed": 4,
            "imu.gyro_bias_rw_dps_per_sqrt_s": 0.02,
            "imu.gyro_scale_error": [0.0, 0.0, 0.02],
        }
    )
    return simulate(sc)


def test_gyro_bias_random_walk_has_the_configured_scale(drifting_gyro_run):
    r = drifting_gyro_run
    bias = r.sensors.gyro_bias_dps
    sc = r.scenario["imu"]
    assert bias[0] == pytest.approx(sc["gyro_bias_dps"])
    # increments over 1 s are independent N(0, σ²·1 s) per axis
    inc = np.diff(bias[::100], axis=0).ravel()
    assert len(inc) >= 300
    assert inc.std() == pytest.approx(sc["gyro_bias_rw_dps_per_sqrt_s"], rel=0.15)
    assert abs(inc.mean()) < 3 * sc["gyro_bias_rw_dps_per_sqrt_s"] / math.sqrt(len(inc))
    # variance grows linearly: over 10 s, √10 times the 1 s spread
    inc10 = np.diff(bias[::1000], axis=0).ravel()
    assert inc10.std() == pytest.approx(sc["gyro_bias_rw_dps_per_sqrt_s"] * math.sqrt(10), rel=0.4)


def test_gyro_output_carries_bias_and_scale_error(drifting_gyro_run):
    r = drifting_gyro_run
    true_z_dps = np.degrees(r.walk.yaw_rate_radps)
    resid = r.sensors.gyro_dps - r.sensors.gyro_bias_dps
    resid[:, 2] -= true_z_dps * 1.02
    # what is left is white noise
    one_s = resid[: len(resid) // 100 * 100].reshape(-1, 100, 3).mean(axis=1)
    assert np.abs(one_s).max() < 5 * r.scenario["imu"]["gyro_noise_dps"] / math.sqrt(100)
    # the bias wanders away from its initial value (a real drift, not just noise)
    assert np.abs(r.sensors.gyro_bias_dps[-1] - r.sensors.gyro_bias_dps[0]).max() > 0.05
