"""Board emulator: turns sensor samples and Wi-Fi scans into the CAN frames of firmware/board.dbc and
writes them as can-utils ``candump -L`` lines.

The contract (DBC comments and docs/DESIGN.md):

* board time is a uint32 millisecond counter starting at ``can.board_time_start_ms`` (it wraps at 2**32);
* BOARD_TIME (full time, boot_id) is the first frame and is repeated every 1000 ms;
* each IMU sample (100 Hz) is IMU_ACCEL then IMU_GYRO with the same seq (IMU sample counter mod 256)
  and t_lo_ms = board time mod 256; MAG (50 Hz) and BARO (20 Hz) likewise with their own counters;
* a Wi-Fi scan is WIFI_SCAN_BEGIN(scan_id mod 256, time_ms = board time at scan start), one WIFI_AP per
  access point, WIFI_SCAN_END(scan_id, n_ap), sent as one burst when the results are ready;
* BOARD_STATUS at 1 Hz (offset 500 ms from BOARD_TIME).

Frames at the same board millisecond go out in the order BOARD_TIME, IMU, MAG, BARO, Wi-Fi, status.
Host timestamp = 1700000000 s + (unwrapped) board time + latency; the bus is serial, so each frame
arrives at least one frame time after the previous one (timestamps never decrease). Frame loss
(``can.loss_rate``, seeded) models frames lost between board and logger: the board sent them (n_ap
counts every AP frame sent), the log lacks them, the counters report what the log holds. The very first
BOARD_TIME frame is never dropped so that a log always starts with the time reference.

Values are clamped into each signal's DBC range, then encoded with cantools (``strict=False``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import cantools
import numpy as np

from .radio import Scan
from .sensors import SensorData

EPOCH_US = 1_700_000_000 * 1_000_000
DBC_PATH = Path(__file__).resolve().parents[2] / "firmware" / "board.dbc"
IMU_PERIOD_MS = 10
FW_MAJOR, FW_MINOR = 1, 0

# priority of frames that share a board millisecond
P_TIME, P_IMU, P_MAG, P_BARO, P_WIFI, P_STATUS = range(6)


@dataclass
class BoardOutput:
    lines: list[str]
    counts: dict = field(default_factory=dict)


_DB_CACHE: dict = {}


def load_dbc(path: Path | str = DBC_PATH):
    key = str(path)
    if key not in _DB_CACHE:
        _DB_CACHE[key] = cantools.database.load_file(key)
    return _DB_CACHE[key]


def _clip_signal(db, msg_name: str, sig_name: str, values: np.ndarray) -> np.ndarray:
    sig = db.get_message_by_name(msg_name).get_signal_by_name(sig_name)
    return np.clip(values, sig.minimum, sig.maximum)


def _events(db, sensors: SensorData, scans: list[Scan], n_imu: int, sc: dict):
    """(t_ms since start, priority, name, fields) in emission order."""
    start_ms = int(sc["can"]["board_time_start_ms"])
    boot_id = int(sc["can"]["boot_id"])
    acc = _clip_signal(db, "IMU_ACCEL", "accel_x", sensors.accel_mps2).tolist()
    gyr = _clip_signal(db, "IMU_GYRO", "gyro_x", sensors.gyro_dps).tolist()
    mag = _clip_signal(db, "MAG", "mag_x", sensors.mag_ut).tolist()
    prs = _clip_signal(db, "BARO", "pressure", sensors.pressure_pa).tolist()
    tmp = _clip_signal(db, "BARO", "temperature", sensors.temperature_degc).tolist()
    duration_ms = (n_imu - 1) * IMU_PERIOD_MS

    ev = []
    for t in range(0, duration_ms + 1, 1000):
        ev.append((t, P_TIME, "BOARD_TIME", {"time_ms": (start_ms + t) % 2**32, "boot_id": boot_id}))
    for i in range(n_imu):
        t = i * IMU_PERIOD_MS
        lo = (start_ms + t) % 256
        ax, ay, az = acc[i]
        gx, gy, gz = gyr[i]
        ev.append((t, P_IMU, "IMU_ACCEL", {"accel_x": ax, "accel_y": ay, "accel_z": az, "seq": i % 256, "t_lo_ms": lo}))
        ev.append((t, P_IMU, "IMU_GYRO", {"gyro_x": gx, "gyro_y": gy, "gyro_z": gz, "seq": i % 256, "t_lo_ms": lo}))
    for j, i in enumerate(sensors.mag_idx.tolist()):
        t = i * IMU_PERIOD_MS
        mx, my, mz = mag[j]
        ev.append((t, P_MAG, "MAG", {"mag_x": mx, "mag_y": my, "mag_z": mz, "seq": j % 256,
                                     "t_lo_ms": (start_ms + t) % 256}))
    for j, i in enumerate(sensors.baro_idx.tolist()):
        t = i * IMU_PERIOD_MS
        ev.append((t, P_BARO, "BARO", {"pressure": prs[j], "temperature": tmp[j], "seq": j % 256,
                                       "t_lo_ms": (start_ms + t) % 256}))
    for k, scan in enumerate(scans):
        t = scan.t_ms + int(sc["radio"]["scan_duration_ms"])
        if t > duration_ms:
            continue
        ev.append((t, P_WIFI, "WIFI_SCAN_BEGIN", {"scan_id": k % 256, "time_ms": (start_ms + scan.t_ms) % 2**32}))
        for bssid, rssi, ch in scan.aps:
            ev.append((t, P_WIFI, "WIFI_AP", {"bssid": bssid, "rssi": max(-128, min(127, rssi)), "channel": ch}))
        ev.append((t, P_WIFI, "WIFI_SCAN_END", {"scan_id": k % 256, "n_ap": min(255, len(scan.aps))}))
    baro_t = (sensors.baro_idx * IMU_PERIOD_MS).tolist()
    for t in range(500, duration_ms + 1, 1000):
        j = min(int(np.searchsorted(baro_t, t)), len(tmp) - 1)
        ev.append((t, P_STATUS, "BOARD_STATUS", {
            "tx_overflows": 0, "board_temp": int(round(max(-128, min(127, tmp[j])))),
            "fw_major": FW_MAJOR, "fw_minor": FW_MINOR,
            "imu_ok": 1, "mag_ok": 1, "baro_ok": 1, "wifi_ok": 1}))
    ev.sort(key=lambda e: (e[0], e[1]))  # stable: keeps ACCEL before GYRO, BEGIN/APs/END in order
    return ev


def emulate_board(sensors: SensorData, scans: list[Scan], n_imu: int, sc: dict,
                  rng: np.random.Generator, dbc_path: Path | str = DBC_PATH) -> BoardOutput:
    db = load_dbc(dbc_path)
    can = sc["can"]
    start_ms = int(can["board_time_start_ms"])
    latency_us, frame_us = int(can["latency_us"]), int(can["frame_time_us"])
    events = _events(db, sensors, scans, n_imu, sc)
    lost = rng.random(len(events)) < float(can["loss_rate"])
    lost[0] = False  # the log starts with the first BOARD_TIME

    msgs = {m.name: m for m in db.messages}
    frame_ids = {name: f"{m.frame_id:03X}" for name, m in msgs.items()}
    sent_by_name = {name: 0 for name in msgs}
    dropped_by_name = {name: 0 for name in msgs}
    imu_samples = 0
    lines = []
    prev_us = 0
    last_accel_sent = False
    for n, (t, _prio, name, fields) in enumerate(events):
        host_us = max(EPOCH_US + (start_ms + t) * 1000 + latency_us, prev_us + frame_us)
        prev_us = host_us
        if name == "IMU_ACCEL":
            last_accel_sent = not lost[n]
        if lost[n]:
            dropped_by_name[name] += 1
            continue
        if name == "IMU_GYRO" and last_accel_sent:
            imu_samples += 1
        sent_by_name[name] += 1
        data = msgs[name].encode(fields, strict=False)
        lines.append(f"({host_us // 1_000_000}.{host_us % 1_000_000:06d}) can0 "
                     f"{frame_ids[name]}#{data.hex().upper()}")
    counts = {
        "frames_total": len(lines),
        "frames_dropped": int(lost.sum()),
        "imu_samples": imu_samples,
        "mag_samples": sent_by_name["MAG"],
        "baro_samples": sent_by_name["BARO"],
        "wifi_scans": sent_by_name["WIFI_SCAN_BEGIN"],
        "wifi_ap_frames": sent_by_name["WIFI_AP"],
        "frames_by_name": {k: v for k, v in sent_by_name.items() if v},
        "dropped_by_name": {k: v for k, v in dropped_by_name.items() if v},
    }
    return BoardOutput(lines=lines, counts=counts)
