"""BLE advertisements heard by the board: the world's beacons (``World.beacons``) on the Wi-Fi model's
log-distance path loss with wall and floor attenuation (radio.mean_rssi_dbm, shared, not copied):

    RSSI = rssi_1m − 10 · n · log10(max(d, 1 m)) − Σ W_i (walls crossed) − FL · (floors crossed) + X,
    X ~ N(0, σ²) per advertisement (independent: BLE's fast fading decorrelates within one interval)

with rssi_1m the beacon's measured power, n = ``ble.path_loss_exponent``, σ = ``ble.shadowing_db``,
W = ``radio.wall_loss_db`` (2.4 GHz like Wi-Fi), FL = ``radio.floor_loss_db``; d is 3-D from the board
(sensor height above the walking surface) to the beacon (``z_m`` above its floor). Each beacon
advertises every ``adv_interval_ms`` plus the spec's advDelay U(0, ``ble.adv_jitter_ms``) from a random
phase; an advertisement is heard when its RSSI (rounded to whole dBm) is at least ``ble.floor_dbm`` and
the scanner was listening (probability 1 − ``ble.loss_rate``). Receptions are measured at the walker
sample nearest the advertisement's time. Cost: O(advertisements × walls).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .radio import mean_rssi_dbm
from .walker import Walk
from .world import World


@dataclass
class Advertisements:
    """Heard advertisements, in time order: t_ms (since the simulation start), beacon MAC, RSSI [dBm]."""

    t_ms: np.ndarray
    mac: np.ndarray
    rssi_dbm: np.ndarray

    def __len__(self) -> int:
        return len(self.t_ms)


def empty() -> Advertisements:
    return Advertisements(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64))


def simulate_ble(sc: dict, world: World, walk: Walk, rng: np.random.Generator) -> Advertisements:
    b, r = sc["ble"], sc["radio"]
    if not world.beacons or not b["enabled"] or len(walk.t_s) < 2:
        return empty()
    duration_ms = int(round(walk.t_s[-1] * 1000.0))
    dt_ms = int(round((walk.t_s[1] - walk.t_s[0]) * 1000.0))
    ts, macs, rssis = [], [], []
    for bc in world.beacons:
        n = int(duration_ms / bc.adv_interval_ms) + 2
        gaps = bc.adv_interval_ms + rng.uniform(0.0, b["adv_jitter_ms"], n)
        t = rng.uniform(0.0, bc.adv_interval_ms) + np.concatenate([[0.0], np.cumsum(gaps[:-1])])
        t_ms = np.round(t).astype(np.int64)
        t_ms = t_ms[t_ms <= duration_ms]
        i = np.minimum(np.round(t_ms / dt_ms).astype(int), len(walk.t_s) - 1)
        rx = (
            walk.x_m[i],
            walk.y_m[i],
            walk.level_m[i] + sc["baro"]["sensor_height_m"],
            walk.floor[i],
        )
        tx = (
            np.array([bc.x_m]),
            np.array([bc.y_m]),
            np.array([bc.floor * world.storey_m + bc.z_m]),
            np.array([bc.floor]),
        )
        rssi = mean_rssi_dbm(world, r, bc.rssi_1m_dbm, b["path_loss_exponent"], rx, tx)
        rssi = np.round(rssi + b["shadowing_db"] * rng.standard_normal(rssi.shape))
        heard = (rssi >= b["floor_dbm"]) & (rng.random(len(rssi)) >= b["loss_rate"])
        ts.append(t_ms[heard])
        macs.append(np.full(int(heard.sum()), bc.mac, np.int64))
        rssis.append(np.clip(rssi[heard], -128, 127).astype(np.int64))
    t_all = np.concatenate(ts)
    order = np.argsort(t_all, kind="stable")
    return Advertisements(t_all[order], np.concatenate(macs)[order], np.concatenate(rssis)[order])
