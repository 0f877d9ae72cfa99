"""Inertial, magnetic and barometric sensor models of the board (strapdown, board axes).

Frames: map (x, y, z up), body (x forward, y left, z up; level, yawed by the walking heading), board =
body rotated by the fixed mounting rotation R_bm = Rz(yaw) · Ry(pitch) · Rx(roll) (board axes expressed
in the body frame), so a board-frame vector is v_board = R_bmᵀ · v_body.

* Accelerometer: specific force f = a − g, with g = (0, 0, −9.80665) m/s² in the map frame, so an
  upright, resting board reads +9.81 on z; plus a constant bias and white noise [m/s²].
* Gyroscope: body angular rate (yaw rate about body z), plus a constant bias and white noise [deg/s].
* Magnetometer: earth field of intensity F and inclination (dip) δ; magnetic north lies along map heading
  90° − map_rotation_deg; m_map = F·(cos δ · cos ψn, cos δ · sin ψn, −sin δ); rotated into the board
  frame, plus a hard-iron offset and white noise [µT].
* Barometer: international standard atmosphere, p = p0 · (1 − 2.25577e-5 · h)^5.25588 (≈ −12 Pa/m near
  sea level) at the board height (floor height + sensor height + gait bounce), plus white noise [Pa];
  board temperature warms by 2 °C with a 120 s time constant, plus noise [°C].

Rates: IMU 100 Hz (every walker sample), magnetometer 50 Hz (every 2nd), barometer 20 Hz (every 5th).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .walker import G_MPS2, Walk
from .world import World

IMU_RATE_HZ = 100
MAG_DECIMATION = 2    # 50 Hz
BARO_DECIMATION = 5   # 20 Hz


@dataclass
class SensorData:
    accel_mps2: np.ndarray   # (N, 3) board frame, every IMU sample
    gyro_dps: np.ndarray     # (N, 3)
    mag_idx: np.ndarray      # IMU sample indices of the magnetometer samples
    mag_ut: np.ndarray       # (M, 3)
    baro_idx: np.ndarray     # IMU sample indices of the barometer samples
    pressure_pa: np.ndarray  # (B,)
    temperature_degc: np.ndarray  # (B,)


def mounting_matrix(roll_deg: float, pitch_deg: float, yaw_deg: float) -> np.ndarray:
    """R_bm = Rz(yaw) Ry(pitch) Rx(roll): columns are the board axes expressed in the body frame."""
    r, p, y = (math.radians(a) for a in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def earth_field_map_ut(field_ut: float, dip_deg: float, map_rotation_deg: float) -> np.ndarray:
    """Earth magnetic field in the map frame [µT]."""
    psi_n = math.radians(90.0 - map_rotation_deg)
    dip = math.radians(dip_deg)
    h = field_ut * math.cos(dip)
    return np.array([h * math.cos(psi_n), h * math.sin(psi_n), -field_ut * math.sin(dip)])


def pressure_pa(height_m: np.ndarray, sea_level_pa: float) -> np.ndarray:
    return sea_level_pa * (1.0 - 2.25577e-5 * height_m) ** 5.25588


def simulate_sensors(sc: dict, world: World, walk: Walk, rng: np.random.Generator) -> SensorData:
    imu, mag, baro, mnt = sc["imu"], sc["mag"], sc["baro"], sc["mounting"]
    n = len(walk.t_s)
    R_bm = mounting_matrix(mnt["roll_deg"], mnt["pitch_deg"], mnt["yaw_deg"])

    # accelerometer: the body is level, so gravity enters only on body z
    f_body = walk.accel_body_mps2 + np.array([0.0, 0.0, G_MPS2])
    accel = f_body @ R_bm + np.asarray(imu["accel_bias_mps2"]) + imu["accel_noise_mps2"] * rng.standard_normal((n, 3))

    w_body = np.zeros((n, 3))
    w_body[:, 2] = np.degrees(walk.yaw_rate_radps)
    gyro = w_body @ R_bm + np.asarray(imu["gyro_bias_dps"]) + imu["gyro_noise_dps"] * rng.standard_normal((n, 3))

    mag_idx = np.arange(0, n, MAG_DECIMATION)
    m_map = earth_field_map_ut(mag["field_ut"], mag["dip_deg"], world.map_rotation_deg)
    psi = walk.heading_rad[mag_idx]
    c, s = np.cos(psi), np.sin(psi)
    m_body = np.stack([c * m_map[0] + s * m_map[1], -s * m_map[0] + c * m_map[1],
                       np.full_like(psi, m_map[2])], axis=1)
    mag_ut = m_body @ R_bm + np.asarray(mag["hard_iron_ut"]) + mag["noise_ut"] * rng.standard_normal((len(mag_idx), 3))

    baro_idx = np.arange(0, n, BARO_DECIMATION)
    h = world.floor_height_m + baro["sensor_height_m"] + walk.height_m[baro_idx]
    p = pressure_pa(h, baro["sea_level_pa"]) + baro["noise_pa"] * rng.standard_normal(len(baro_idx))
    t = walk.t_s[baro_idx]
    temp = (baro["temperature_degc"] + 2.0 * (1.0 - np.exp(-t / 120.0))
            + baro["temperature_noise_degc"] * rng.standard_normal(len(baro_idx)))
    return SensorData(accel_mps2=accel, gyro_dps=gyro, mag_idx=mag_idx, mag_ut=mag_ut,
                      baro_idx=baro_idx, pressure_pa=p, temperature_degc=temp)
