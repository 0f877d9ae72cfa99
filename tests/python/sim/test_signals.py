"""Physical plausibility of the simulated signals: one detectable vertical peak per step, none while
standing, gyro yaw matching the heading change, magnetometer and barometer levels."""

from __future__ import annotations

import numpy as np
import pytest
from stridefix_sim.pipeline import simulate
from stridefix_sim.scenario import default_scenario
from stridefix_sim.sensors import earth_field_map_ut


@pytest.fixture(scope="module")
def mounted_run():
    """GIVEN a board mounted tilted and turned on the body, 45 s including the first pause."""
    sc = default_scenario().with_overrides(
        **{
            "seed": 3,
            "duration_s": 45.0,
            "mounting.roll_deg": 25.0,
            "mounting.pitch_deg": -15.0,
            "mounting.yaw_deg": 90.0,
            "walk.pause": [{"at_m": 20.0, "duration_s": 6.0}],
        }
    )
    return simulate(sc)


def test_one_vertical_peak_per_step_none_while_still(mounted_run, step_detector):
    r = mounted_run
    peaks_t = r.walk.t_s[step_detector(r.sensors.accel_mps2, threshold_mps2=1.0)]
    steps_t = r.walk.step_t_s[r.walk.step_t_s <= r.walk.t_s[-1]]
    assert abs(len(peaks_t) - len(steps_t)) <= max(1, 0.01 * len(steps_t))
    # every detected peak is at a true step, none while standing
    nearest = np.abs(peaks_t[:, None] - steps_t[None, :]).min(axis=1)
    assert np.all(nearest < 0.05)
    still = r.walk.speed_mps[(peaks_t * 100).round().astype(int)] == 0
    assert not still.any()


def test_gyro_yaw_follows_heading(mounted_run):
    r = mounted_run
    g = r.sensors.accel_mps2.mean(axis=0)
    up = g / np.linalg.norm(g)
    bias_removed = r.sensors.gyro_dps - r.sensors.gyro_dps[: int(2.5 * 100)].mean(axis=0)  # still at start
    yaw_deg = np.cumsum(bias_removed @ up) * 0.01
    true_deg = np.degrees(r.walk.heading_rad - r.walk.heading_rad[0])
    assert true_deg[-1] > 80  # the run includes the first corner
    # bias drift and the 1 % scale error stay within a few degrees over 45 s
    assert yaw_deg[-1] == pytest.approx(true_deg[-1], abs=3.0)


def test_magnetometer_and_barometer_levels(mounted_run):
    r = mounted_run
    sc = r.scenario["mag"]
    clean = r.sensors.mag_zone_w == 0
    assert 0.5 < clean.mean() < 1.0  # the run passes one disturbance zone
    norm = np.linalg.norm(r.sensors.mag_ut - np.asarray(sc["hard_iron_ut"]), axis=1)
    assert norm[clean].mean() == pytest.approx(sc["field_ut"], abs=0.2)
    # the hard-iron offset is small: the raw norm stays within ~1.2 µT of the field outside zones
    assert np.all(
        np.abs(np.linalg.norm(r.sensors.mag_ut[clean], axis=1) - sc["field_ut"]) < 1.2 + 5 * sc["noise_ut"]
    )
    # at rest (start), tilt-compensated horizontal field points to magnetic north (heading 90° − rotation)
    field_map = earth_field_map_ut(sc["field_ut"], sc["dip_deg"], r.world.map_rotation_deg)
    assert np.degrees(np.arctan2(field_map[1], field_map[0])) == pytest.approx(
        90.0 - r.world.map_rotation_deg
    )
    p = r.sensors.pressure_pa - r.sensors.baro_drift_pa
    assert p.mean() == pytest.approx(101325.0 - 12.0 * 1.1, abs=1.0)
    assert 1.0 < p.std() < 2.5
    assert np.abs(r.sensors.baro_drift_pa).max() < 15.0  # weather: ~0.33 Pa/√s over 45 s
    assert 20 < r.sensors.temperature_degc.mean() < 26


@pytest.mark.parametrize("cadence_hz", [1.6, 2.0])
def test_cadence_setting_is_honoured(cadence_hz):
    r = simulate(default_scenario().with_overrides(**{"duration_s": 20.0, "walk.cadence_hz": cadence_hz}))
    st = r.walk.step_t_s[r.walk.step_t_s <= 20.0]
    assert (len(st) - 1) / (st[-1] - st[0]) == pytest.approx(cadence_hz, rel=0.05)
