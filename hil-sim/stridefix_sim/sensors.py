"""Inertial, magnetic and barometric sensor models of the board (strapdown, board axes).

Frames: map (x, y, z up), body (x forward, y left, z up; level, yawed by the walking heading), board =
body rotated by the fixed mounting rotation R_bm = Rz(yaw) · Ry(pitch) · Rx(roll) (board axes expressed
in the body frame), so a board-frame vector is v_board = R_bmᵀ · v_body.

* Accelerometer: specific force f = a − g, with g = (0, 0, −9.80665) m/s² in the map frame, so an
  upright, resting board reads +9.81 on z; plus a constant bias and white noise [m/s²].
* Gyroscope: body angular rate (yaw rate about body z) in board axes, times (1 + per-axis scale error),
  plus a bias that starts at ``imu.gyro_bias_dps`` and random-walks (rate random walk: after t seconds
  its std per axis is ``gyro_bias_rw_dps_per_sqrt_s`` · √t), plus white noise [deg/s].
* Magnetometer: earth field of intensity F and inclination (dip) δ; magnetic north lies along map heading
  90° − map_rotation_deg; m_map = F·(cos δ · cos ψn, cos δ · sin ψn, −sin δ). Inside the world's
  disturbance zones (``world.MagZone``, scaled by ``mag.disturbance_scale``) F, ψn and δ are perturbed;
  rotated into the board frame, plus a hard-iron offset and white noise [µT].
* Barometer: international standard atmosphere, p = p0 · (1 − 2.25577e-5 · h)^5.25588 (≈ −12.0 Pa/m
  near sea level) at the board height (floor-0 ground + sensor height + level under the feet + gait
  bounce), plus weather drift (a random walk, std ``drift_pa_per_sqrt_h`` after one hour, knots every
  10 s, linear in between) and white noise [Pa]; board temperature warms by 2 °C with a 120 s time
  constant, plus noise [°C].

Rates: IMU 100 Hz (every walker sample), magnetometer 50 Hz (every 2nd), barometer 20 Hz (every 5th).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .gait import G_MPS2
from .walker import Walk
from .world import World

IMU_RATE_HZ = 100
MAG_DECIMATION = 2  # 50 Hz
BARO_DECIMATION = 5  # 20 Hz


@dataclass
class SensorData:
    accel_mps2: np.ndarray  # (N, 3) board frame, every IMU sample
    gyro_dps: np.ndarray  # (N, 3)
    mag_idx: np.ndarray  # IMU sample indices of the magnetometer samples
    mag_ut: np.ndarray  # (M, 3)
    baro_idx: np.ndarray  # IMU sample indices of the barometer samples
    pressure_pa: np.ndarray  # (B,)
    temperature_degc: np.ndarray  # (B,)
    gyro_bias_dps: np.ndarray | None = None  # (N, 3) the true gyro bias track
    mag_zone_w: np.ndarray | None = None  # (M,) disturbance weight at each magnetometer sample (0 = clean)
    baro_drift_pa: np.ndarray | None = None  # (B,) the true weather drift


def mounting_matrix(roll_deg: float, pitch_deg: float, yaw_deg: float) -> np.ndarray:
    """R_bm = Rz(yaw) Ry(pitch) Rx(roll): columns are the board axes expressed in the body frame."""
    r, p, y = (math.radians(a) for a in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def earth_field_map_ut(field_ut, dip_deg, map_rotation_deg) -> np.ndarray:
    """Earth magnetic field in the map frame [µT]; array arguments give one row per element."""
    psi_n = np.radians(90.0 - np.asarray(map_rotation_deg, float))
    dip = np.radians(np.asarray(dip_deg, float))
    h = field_ut * np.cos(dip)
    return np.stack(
        np.broadcast_arrays(h * np.cos(psi_n), h * np.sin(psi_n), -field_ut * np.sin(dip)), axis=-1
    )


def local_field_map_ut(world: World, mag: dict, x_m: np.ndarray, y_m: np.ndarray, floor: np.ndarray):
    """The (possibly disturbed) field at positions (N,) in the map frame (N, 3) and the zone weight (N,)."""
    gain = np.ones(len(x_m))
    d_az = np.zeros(len(x_m))
    d_dip = np.zeros(len(x_m))
    w_max = np.zeros(len(x_m))
    k = mag["disturbance_scale"]
    for z in world.mag_zones:
        w = z.weight(x_m, y_m, floor) * k
        gain += w * (z.gain - 1.0)
        d_az += w * z.azimuth_deg
        d_dip += w * z.dip_deg
        w_max = np.maximum(w_max, w)
    m = earth_field_map_ut(mag["field_ut"] * gain, mag["dip_deg"] + d_dip, world.map_rotation_deg - d_az)
    return m, w_max


def pressure_pa(height_m: np.ndarray, sea_level_pa: float) -> np.ndarray:
    return sea_level_pa * (1.0 - 2.25577e-5 * height_m) ** 5.25588


def simulate_sensors(sc: dict, world: World, walk: Walk, rng: np.random.Generator) -> SensorData:
    imu, mag, baro, mnt = sc["imu"], sc["mag"], sc["baro"], sc["mounting"]
    n = len(walk.t_s)
    R_bm = mounting_matrix(mnt["roll_deg"], mnt["pitch_deg"], mnt["yaw_deg"])

    # accelerometer: the body is level, so gravity enters only on body z
    f_body = walk.accel_body_mps2 + np.array([0.0, 0.0, G_MPS2])
    accel = (
        f_body @ R_bm
        + np.asarray(imu["accel_bias_mps2"])
        + imu["accel_noise_mps2"] * rng.standard_normal((n, 3))
    )

    w_body = np.zeros((n, 3))
    w_body[:, 2] = np.degrees(walk.yaw_rate_radps)
    dt = float(walk.t_s[1] - walk.t_s[0]) if n > 1 else 0.01
    steps = imu["gyro_bias_rw_dps_per_sqrt_s"] * math.sqrt(dt) * rng.standard_normal((n, 3))
    steps[0] = 0.0
    bias = np.asarray(imu["gyro_bias_dps"]) + np.cumsum(steps, axis=0)
    gyro = (
        (w_body @ R_bm) * (1.0 + np.asarray(imu["gyro_scale_error"]))
        + bias
        + imu["gyro_noise_dps"] * rng.standard_normal((n, 3))
    )

    mag_idx = np.arange(0, n, MAG_DECIMATION)
    m_map, zone_w = local_field_map_ut(world, mag, walk.x_m[mag_idx], walk.y_m[mag_idx], walk.floor[mag_idx])
    psi = walk.heading_rad[mag_idx]
    c, s = np.cos(psi), np.sin(psi)
    m_body = np.stack(
        [c * m_map[:, 0] + s * m_map[:, 1], -s * m_map[:, 0] + c * m_map[:, 1], m_map[:, 2]], axis=1
    )
    mag_ut = (
        m_body @ R_bm
        + np.asarray(mag["hard_iron_ut"])
        + mag["noise_ut"] * rng.standard_normal((len(mag_idx), 3))
    )

    baro_idx = np.arange(0, n, BARO_DECIMATION)
    t = walk.t_s[baro_idx]
    h = world.ground_z_m + baro["sensor_height_m"] + walk.height_m[baro_idx]
    knot_s = 10.0
    n_knots = int(math.ceil(t[-1] / knot_s)) + 2 if len(t) else 2
    sigma = baro["drift_pa_per_sqrt_h"] / 60.0 * math.sqrt(knot_s)  # per knot
    knots = np.concatenate([[0.0], np.cumsum(sigma * rng.standard_normal(n_knots - 1))])
    drift = np.interp(t, np.arange(n_knots) * knot_s, knots)
    p = pressure_pa(h, baro["sea_level_pa"]) + drift + baro["noise_pa"] * rng.standard_normal(len(baro_idx))
    temp = (
        baro["temperature_degc"]
        + 2.0 * (1.0 - np.exp(-t / 120.0))
        + baro["temperature_noise_degc"] * rng.standard_normal(len(baro_idx))
    )
    return SensorData(
        accel_mps2=accel,
        gyro_dps=gyro,
        mag_idx=mag_idx,
        mag_ut=mag_ut,
        baro_idx=baro_idx,
        pressure_pa=p,
        temperature_degc=temp,
        gyro_bias_dps=bias,
        mag_zone_w=zone_w,
        baro_drift_pa=drift,
    )
