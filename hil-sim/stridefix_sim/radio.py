"""Wi-Fi scan model: log-distance path loss with per-wall attenuation (multi-wall model, cf. COST-231
Motley-Keenan; Seidel & Rappaport 1992).

    RSSI = P0 − 10 · n · log10(d / 1 m) − Σ W_i (walls crossed) − FL · (floors crossed) − B + X,   X ~ N(0, σ²)
    P0   = tx_power_dbm − FSPL(1 m, f),   FSPL(1 m, f) = 20 · log10(f / MHz) − 27.55 dB

d is the 3-D distance from the board (walking-surface level + sensor height) to the access point
(ceiling of its floor, 2.8 m above it); walls are the floor plan's segments crossed by the plan-view line
between them (every floor has the same plan), each costing ``radio.wall_loss_db`` unless the world
gives that wall its own loss (``World.walls_loss_db``: the aadr2015 foyer's concrete core, 15 dB);
B = ``radio.body_loss_db`` · (1 − cos β) / 2 is the wearer's body shadowing, β the angle between the
direction the person faces and the bearing to the AP (0 when facing it, the full loss with the AP
behind: why a survey scans in four orientations); floors crossed = |AP floor − the person's floor|, FL =
``radio.floor_loss_db`` (15 dB, cf. the ITU-R P.1238 floor penetration factor). The result is
rounded to whole dBm as a receiver reports it; access points below the detection floor (−95 dBm) are
not reported. Scans start every U(min, max) seconds (2–4 s); each returns every AP above the floor, in
channel order, measured at the position where the scan started. In survey mode the scans happen at
the planned times instead (``Walk.scan_plan``: standing at a calibration point) and nowhere else.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from stridefix_common.physics import AP_HEIGHT_M

from .walker import Walk
from .world import World


@dataclass
class Scan:
    t_ms: int  # scan start, ms since the simulation start
    aps: list[tuple[int, int, int]]  # (bssid, rssi_dbm, channel)


def walls_crossed(
    px: np.ndarray, py: np.ndarray, ax: np.ndarray, ay: np.ndarray, walls: np.ndarray
) -> np.ndarray:
    """Count of walls properly crossed by segments (px,py)→(ax,ay); inputs broadcast to shape S, walls (W,4)."""
    px, py, ax, ay = (np.asarray(v, float)[..., None] for v in (px, py, ax, ay))
    x0, y0, x1, y1 = walls[:, 0], walls[:, 1], walls[:, 2], walls[:, 3]

    def orient(ox, oy, bx, by, cx, cy):
        return (bx - ox) * (cy - oy) - (by - oy) * (cx - ox)

    d1 = orient(x0, y0, x1, y1, px, py)
    d2 = orient(x0, y0, x1, y1, ax, ay)
    d3 = orient(px, py, ax, ay, x0, y0)
    d4 = orient(px, py, ax, ay, x1, y1)
    hit = (d1 * d2 < 0) & (d3 * d4 < 0)
    return hit.sum(axis=-1)


def walls_loss_db(px, py, ax, ay, walls: np.ndarray, loss_db: np.ndarray) -> np.ndarray:
    """Total loss [dB] of the walls crossed by segments (px,py)→(ax,ay); ``loss_db`` (W,) per wall."""
    px, py, ax, ay = (np.asarray(v, float)[..., None] for v in (px, py, ax, ay))
    x0, y0, x1, y1 = walls[:, 0], walls[:, 1], walls[:, 2], walls[:, 3]

    def orient(ox, oy, bx, by, cx, cy):
        return (bx - ox) * (cy - oy) - (by - oy) * (cx - ox)

    hit = (orient(x0, y0, x1, y1, px, py) * orient(x0, y0, x1, y1, ax, ay) < 0) & (
        orient(px, py, ax, ay, x0, y0) * orient(px, py, ax, ay, x1, y1) < 0
    )
    return (hit * loss_db).sum(axis=-1)


def mean_rssi_dbm(world: World, r: dict, p0_dbm, exponent: float, rx: tuple, tx: tuple) -> np.ndarray:
    """The model's mean RSSI [dBm] without shadowing: P0 − 10·n·log10(max(d, 1 m)) − walls − floors.

    ``rx`` = (x, y, z, floor) of the receiver and ``tx`` = (x, y, z, floor) of the transmitter
    (arrays that broadcast, z in metres above floor 0); ``p0_dbm`` the RSSI at 1 m; walls cost
    ``r["wall_loss_db"]`` unless the world gives a wall its own loss, floors ``r["floor_loss_db"]`` each.
    Shared by the Wi-Fi scans (here) and the BLE advertisements (ble.py)."""
    px, py, pz, pf = rx
    ax, ay, az, af = tx
    d = np.sqrt((px - ax) ** 2 + (py - ay) ** 2 + (pz - az) ** 2)
    args = (
        np.broadcast_to(px, d.shape),
        np.broadcast_to(py, d.shape),
        np.broadcast_to(ax, d.shape),
        np.broadcast_to(ay, d.shape),
        world.walls_m,
    )
    if world.walls_loss_db is None:
        wall_db = r["wall_loss_db"] * walls_crossed(*args)
    else:
        wall_db = walls_loss_db(
            *args, np.where(np.isnan(world.walls_loss_db), r["wall_loss_db"], world.walls_loss_db)
        )
    return (
        p0_dbm
        - 10.0 * exponent * np.log10(np.maximum(d, 1.0))
        - wall_db
        - r["floor_loss_db"] * np.abs(af - pf)
    )


def scan_times_ms(duration_ms: int, rng: np.random.Generator, r: dict) -> np.ndarray:
    times = []
    t = rng.uniform(0.5, 2.0)
    lo, hi = r["scan_interval_min_s"], r["scan_interval_max_s"]
    while True:
        t_ms = int(round(t * 1000.0))
        if t_ms + r["scan_duration_ms"] > duration_ms:
            break
        times.append(t_ms)
        t += rng.uniform(lo, hi)
    return np.asarray(times, dtype=np.int64)


def simulate_scans(sc: dict, world: World, walk: Walk, rng: np.random.Generator) -> list[Scan]:
    r = sc["radio"]
    duration_ms = int(round(walk.t_s[-1] * 1000.0))
    if sc["survey"]["enabled"]:
        t_ms = np.asarray(
            [p[0] for p in walk.scan_plan if p[0] + r["scan_duration_ms"] <= duration_ms], dtype=np.int64
        )
    else:
        t_ms = scan_times_ms(duration_ms, rng, r)
    if len(t_ms) == 0:
        return []
    dt_ms = int(round((walk.t_s[1] - walk.t_s[0]) * 1000.0)) if len(walk.t_s) > 1 else 10
    idx = np.minimum(np.round(t_ms / dt_ms).astype(int), len(walk.t_s) - 1)
    px, py = walk.x_m[idx][:, None], walk.y_m[idx][:, None]
    pz = (walk.level_m[idx] + sc["baro"]["sensor_height_m"])[:, None]
    pf = walk.floor[idx][:, None]
    aps = world.aps
    ax = np.array([a.x_m for a in aps])[None, :]
    ay = np.array([a.y_m for a in aps])[None, :]
    af = np.array([a.floor for a in aps])[None, :]
    az = af * world.storey_m + AP_HEIGHT_M
    tx = np.array([a.tx_power_dbm for a in aps])
    f_mhz = np.array([a.freq_mhz for a in aps], dtype=float)
    p0 = tx - (20.0 * np.log10(f_mhz) - 27.55)
    rssi = mean_rssi_dbm(world, r, p0[None, :], r["path_loss_exponent"], (px, py, pz, pf), (ax, ay, az, af))
    rssi = rssi + r["shadowing_db"] * rng.standard_normal(rssi.shape)
    if r["body_loss_db"] > 0:
        facing = walk.heading_rad[idx][:, None]
        rssi = rssi - r["body_loss_db"] * 0.5 * (1.0 - np.cos(np.arctan2(ay - py, ax - px) - facing))
    rssi = np.clip(np.round(rssi), -128, 127).astype(int)
    order = sorted(range(len(aps)), key=lambda j: (aps[j].channel, aps[j].bssid))
    scans = []
    for i, t in enumerate(t_ms):
        heard = [
            (aps[j].bssid, int(rssi[i, j]), aps[j].channel) for j in order if rssi[i, j] >= r["floor_dbm"]
        ]
        scans.append(Scan(t_ms=int(t), aps=heard))
    return scans
