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
BOARD_TIME frame is never dropped so that a log always starts with the time reference. The
``[faults]`` table adds board resets, a stuck BOARD_TIME, a failed IMU, implausible samples and bus
faults (``faults.py``): resets through the board clock that ``_events`` uses for every time and
counter, the stuck BOARD_TIME and the failed IMU on what ``_events`` sends, the rest on the ordered
frames; with every fault off none of it runs.

Values are clamped into each signal's DBC range, then encoded per message type at once with numpy
(``pack``: the DBC's scale, offset, start bit and length, the same bytes as cantools'
``encode(strict=False)``; a test compares them frame by frame), so an hour of board traffic takes a few
seconds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import cantools
import numpy as np
from stridefix_common import dbc

from . import faults as flt
from .radio import Scan
from .sensors import SensorData

if TYPE_CHECKING:
    from .pipeline import Sources

EPOCH_US = 1_700_000_000 * 1_000_000
DBC_PATH = dbc.DBC_PATH
IMU_PERIOD_MS = 10
FW_MAJOR, FW_MINOR = 1, 0

# priority of frames that share a board millisecond
P_TIME, P_IMU, P_MAG, P_BARO, P_WIFI, P_BLE, P_GNSS, P_LANDMARK, P_STATUS = range(9)


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


class _Frames:
    """Events of the run as parallel arrays: board ms, priority, insertion order, message, raw payload."""

    def __init__(self):
        self.parts: list[tuple] = []  # (t_ms, priority, name, payload words, insertion index)
        self.n = 0

    def add(self, name: str, t_ms, prio: int, payload: np.ndarray, ins: np.ndarray | None = None) -> None:
        t = np.asarray(t_ms, dtype=np.int64)
        if ins is None:
            ins = self.n + np.arange(len(t), dtype=np.int64)
            self.n += len(t)
        self.parts.append((t, prio, name, payload, ins))

    def reserve(self, k: int) -> int:
        base = self.n
        self.n += k
        return base


def pack(msg, fields: dict) -> np.ndarray:
    """Encode many frames of one DBC message at once: ``fields`` maps every signal name to an array (or
    a scalar) of physical values; returns the frames' data as little-endian uint64 words. Same bytes as
    ``msg.encode(..., strict=False)`` for in-range values: raw = round((value − offset) / scale), half to
    even like Python's round, two's complement for signed signals (the DBC has only Intel signals)."""
    sizes = [np.size(v) for v in fields.values() if np.ndim(v) > 0]
    n = sizes[0] if sizes else 1
    word = np.zeros(n, dtype=np.uint64)
    for sig in msg.signals:
        if sig.byte_order != "little_endian" or sig.is_float:
            raise NotImplementedError(f"{msg.name}.{sig.name}: only little-endian integer signals")
        v = np.broadcast_to(np.asarray(fields[sig.name]), (n,))
        if np.issubdtype(v.dtype, np.integer) and sig.scale == 1 and sig.offset == 0:
            raw = v.astype(np.int64)
        else:
            raw = np.round((v.astype(np.float64) - sig.offset) / sig.scale).astype(np.int64)
        mask = np.uint64((1 << sig.length) - 1)
        word |= (raw.view(np.uint64) & mask) << np.uint64(sig.start)
    return word


def _events(
    db,
    sensors: SensorData,
    scans: list[Scan],
    n_imu: int,
    sc: dict,
    clock: flt.BoardClock,
    rec: flt.FaultRecord,
    sources: Sources | None = None,
) -> _Frames:
    """Every frame the board sends, unsorted (``emulate_board`` orders them by simulated ms, then
    priority, then the order they are added here). ``clock`` gives board time and counter restarts
    (board resets); frames while the board reboots are not sent (counted in ``rec``)."""
    msgs = {m.name: m for m in db.messages}
    acc = _clip_signal(db, "IMU_ACCEL", "accel_x", sensors.accel_mps2)
    gyr = _clip_signal(db, "IMU_GYRO", "gyro_x", sensors.gyro_dps)
    mag = _clip_signal(db, "MAG", "mag_x", sensors.mag_ut)
    prs = _clip_signal(db, "BARO", "pressure", sensors.pressure_pa)
    tmp = _clip_signal(db, "BARO", "temperature", sensors.temperature_degc)
    duration_ms = (n_imu - 1) * IMU_PERIOD_MS
    ev = _Frames()

    t, seg = clock.periodic(0, 1000, duration_ms)
    boot = np.asarray(clock.boot_ids, dtype=np.int64)[seg] if clock.resets else clock.boot_ids[0]
    fc = sc.get("faults")
    time_ms = flt.board_time_sent(clock, t, fc, rec)
    ev.add("BOARD_TIME", t, P_TIME, pack(msgs["BOARD_TIME"], {"time_ms": time_ms, "boot_id": boot}))

    def sent(t: np.ndarray, *cols: np.ndarray, frames: int = 1) -> tuple:
        """(t, seq, t_lo_ms, cols) of the samples a sending boot took (all of them without resets);
        ``frames``: frames per sample."""
        if not clock.resets:
            return (t, np.arange(len(t), dtype=np.int64) % 256, clock.board_ms(t) % 256, *cols)
        seg = clock.segment(t)
        ok = seg >= 0
        rec.unsent_reset += int(np.sum(~ok)) * frames
        t, seg = t[ok], seg[ok]
        return (t, clock.counter(seg) % 256, clock.board_ms(t, seg) % 256, *(c[ok] for c in cols))

    t, seq, lo, acc, gyr = sent(np.arange(n_imu, dtype=np.int64) * IMU_PERIOD_MS, acc, gyr, frames=2)
    flt.imu_failed(db, t, acc, gyr, fc, rec)
    i = np.arange(len(t), dtype=np.int64)
    base = ev.reserve(2 * len(t))  # ACCEL and GYRO of a sample alternate
    ev.add(
        "IMU_ACCEL",
        t,
        P_IMU,
        pack(
            msgs["IMU_ACCEL"],
            {"accel_x": acc[:, 0], "accel_y": acc[:, 1], "accel_z": acc[:, 2], "seq": seq, "t_lo_ms": lo},
        ),
        ins=base + 2 * i,
    )
    ev.add(
        "IMU_GYRO",
        t,
        P_IMU,
        pack(
            msgs["IMU_GYRO"],
            {"gyro_x": gyr[:, 0], "gyro_y": gyr[:, 1], "gyro_z": gyr[:, 2], "seq": seq, "t_lo_ms": lo},
        ),
        ins=base + 2 * i + 1,
    )
    t, seq, lo, mag = sent(sensors.mag_idx.astype(np.int64) * IMU_PERIOD_MS, mag)
    ev.add(
        "MAG",
        t,
        P_MAG,
        pack(
            msgs["MAG"],
            {"mag_x": mag[:, 0], "mag_y": mag[:, 1], "mag_z": mag[:, 2], "seq": seq, "t_lo_ms": lo},
        ),
    )
    baro_t = sensors.baro_idx.astype(np.int64) * IMU_PERIOD_MS
    t, seq, lo, prs_sent, tmp_sent = sent(baro_t, prs, tmp)
    ev.add(
        "BARO",
        t,
        P_BARO,
        pack(msgs["BARO"], {"pressure": prs_sent, "temperature": tmp_sent, "seq": seq, "t_lo_ms": lo}),
    )
    # Wi-Fi: BEGIN, one AP frame per access point, END; in scan order
    wifi = {"WIFI_SCAN_BEGIN": [], "WIFI_AP": [], "WIFI_SCAN_END": []}
    k_ins = 0
    scan_ids = [0] * len(clock.boot_ids)  # scan_id restarts at each boot
    for scan in scans:
        t_res = scan.t_ms + int(sc["radio"]["scan_duration_ms"])
        if t_res > duration_ms:
            continue
        k = int(clock.segment(np.array([scan.t_ms]))[0])
        if clock.resets and (k < 0 or int(clock.segment(np.array([t_res]))[0]) != k):
            rec.scans_lost_reset += 1  # a reset interrupted it: the board never sends it
            continue
        sid = scan_ids[k] % 256
        scan_ids[k] += 1
        wifi["WIFI_SCAN_BEGIN"].append((t_res, k_ins, sid, int(clock.board_ms(np.array([scan.t_ms]))[0]), 0))
        k_ins += 1
        for bssid, rssi, ch in scan.aps:
            wifi["WIFI_AP"].append((t_res, k_ins, bssid, max(-128, min(127, rssi)), ch))
            k_ins += 1
        wifi["WIFI_SCAN_END"].append((t_res, k_ins, sid, min(255, len(scan.aps)), 0))
        k_ins += 1
    base = ev.reserve(k_ins)
    names = {
        "WIFI_SCAN_BEGIN": ("scan_id", "time_ms"),
        "WIFI_AP": ("bssid", "rssi", "channel"),
        "WIFI_SCAN_END": ("scan_id", "n_ap"),
    }
    for name, rows in wifi.items():
        if not rows:
            continue
        a = np.asarray(rows, dtype=np.int64)
        ev.add(
            name,
            a[:, 0],
            P_WIFI,
            pack(msgs[name], {f: a[:, 2 + c] for c, f in enumerate(names[name])}),
            ins=base + a[:, 1],
        )
    if sources is not None:
        _source_frames(ev, msgs, sources, sc, clock, rec, sent, duration_ms)
    t, _ = clock.periodic(500, 1000, duration_ms)
    j = np.minimum(np.searchsorted(baro_t, t), len(tmp) - 1)
    ev.add(
        "BOARD_STATUS",
        t,
        P_STATUS,
        pack(
            msgs["BOARD_STATUS"],
            {
                "tx_overflows": 0,
                "board_temp": np.round(np.clip(tmp[j], -128, 127)).astype(np.int64),
                "fw_major": FW_MAJOR,
                "fw_minor": FW_MINOR,
                "imu_ok": 1,
                "mag_ok": 1,
                "baro_ok": 1,
                "wifi_ok": 1,
            },
        ),
    )
    return ev


def _source_frames(
    ev: _Frames, msgs: dict, src: Sources, sc: dict, clock, rec, sent, duration_ms: int
) -> None:
    """BLE_ADV (one per advertisement heard, at its reception), LANDMARK (``landmark.latency_ms`` after
    the read; t_lo_ms = the read's board time mod 256) and GNSS_INFO + GNSS_POSITION (``gnss.latency_ms``
    after the fix; time_ms = the fix's full board time). A source sample taken while the board was down,
    or whose frame would fall in another boot than the sample, is not sent (board resets)."""
    ad = src.ble
    if len(ad):
        t, _, lo, mac, rssi = sent(ad.t_ms.astype(np.int64), ad.mac, ad.rssi_dbm)
        ev.add("BLE_ADV", t, P_BLE, pack(msgs["BLE_ADV"], {"beacon_id": mac, "rssi": rssi, "t_lo_ms": lo}))

    def same_boot(t_a: np.ndarray, t_b: np.ndarray) -> np.ndarray:
        if not clock.resets:
            return np.ones(len(t_a), bool)
        seg_a = clock.segment(t_a)
        ok = (seg_a >= 0) & (seg_a == clock.segment(t_b))
        rec.unsent_reset += int(np.sum(~ok))
        return ok

    if src.landmarks:
        t_read = np.array([e.t_ms for e in src.landmarks], np.int64)
        t_tx = t_read + int(sc["landmark"]["latency_ms"])
        ok = (t_tx <= duration_ms) & same_boot(t_read, t_tx)
        sel = [e for e, k in zip(src.landmarks, ok) if k]
        if sel:
            fields = {
                "x": np.array([e.x_m for e in sel]),
                "y": np.array([e.y_m for e in sel]),
                "floor": np.array([e.floor for e in sel], np.int64),
                "t_lo_ms": clock.board_ms(t_read[ok]) % 256,
            }
            ev.add("LANDMARK", t_tx[ok], P_LANDMARK, pack(msgs["LANDMARK"], fields))
    fx = src.gnss
    if len(fx):
        t_tx = fx.t_ms.astype(np.int64) + int(sc["gnss"]["latency_ms"])
        ok = (t_tx <= duration_ms) & same_boot(fx.t_ms.astype(np.int64), t_tx)
        n = int(ok.sum())
        base = ev.reserve(2 * n)  # INFO then POSITION of the same fix
        i = np.arange(n, dtype=np.int64)
        info = {
            "time_ms": clock.board_ms(fx.t_ms.astype(np.int64)[ok]),
            "altitude": fx.alt_m[ok],
            "accuracy": np.clip(fx.accuracy_m[ok], 0.0, 409.5),
        }
        ev.add("GNSS_INFO", t_tx[ok], P_GNSS, pack(msgs["GNSS_INFO"], info), ins=base + 2 * i)
        pos = {"latitude": fx.lat_deg[ok], "longitude": fx.lon_deg[ok]}
        ev.add("GNSS_POSITION", t_tx[ok], P_GNSS, pack(msgs["GNSS_POSITION"], pos), ins=base + 2 * i + 1)


def _digits(v: np.ndarray, width: int) -> np.ndarray:
    """(n, width) ASCII digits of non-negative integers, zero-padded."""
    p = 10 ** np.arange(width - 1, -1, -1, dtype=np.int64)
    return (48 + (v[:, None] // p) % 10).astype(np.uint8)


def _candump_lines(host_us: np.ndarray, code: np.ndarray, word: np.ndarray, db) -> list[str]:
    """``(sssssssssss.uuuuuu) can0 III#DDDDDDDDDDDDDDDD`` lines (candump -L), built as one byte array."""
    msgs = db.messages
    n = len(host_us)
    sec, usec = host_us // 1_000_000, host_us % 1_000_000
    if n == 0:
        return []
    if any(m.length != 8 for m in msgs) or sec.min() < 10**9 or sec.max() >= 10**10:  # general (slow) path
        data = word.astype("<u8").view(np.uint8).reshape(-1, 8)
        return [
            f"({h // 1_000_000}.{h % 1_000_000:06d}) can0 {msgs[c].frame_id:03X}#"
            f"{bytes(d[: msgs[c].length]).hex().upper()}"
            for h, c, d in zip(host_us.tolist(), code.tolist(), data)
        ]
    hexd = np.frombuffer(b"0123456789ABCDEF", dtype=np.uint8)
    ids = np.array([list(f"{m.frame_id:03X}".encode()) for m in msgs], dtype=np.uint8)
    data = word.astype("<u8").view(np.uint8).reshape(-1, 8)
    row = np.empty((n, 45), dtype=np.uint8)
    row[:, 0] = ord("(")
    row[:, 1:11] = _digits(sec, 10)
    row[:, 11] = ord(".")
    row[:, 12:18] = _digits(usec, 6)
    row[:, 18:25] = np.frombuffer(b") can0 ", dtype=np.uint8)
    row[:, 25:28] = ids[code]
    row[:, 28] = ord("#")
    row[:, 29:45:2] = hexd[data >> 4]
    row[:, 30:46:2] = hexd[data & 15]
    text = row.tobytes().decode("ascii")
    return [text[i : i + 45] for i in range(0, len(text), 45)]


def emulate_board(
    sensors: SensorData,
    scans: list[Scan],
    n_imu: int,
    sc: dict,
    rng: np.random.Generator,
    dbc_path: Path | str = DBC_PATH,
    fault_rng: np.random.Generator | None = None,
    sources: Sources | None = None,
) -> BoardOutput:
    """The board's frames as candump lines; ``rng`` draws the random loss, ``fault_rng`` the
    ``[faults]`` (faults.py; needed only when one is on)."""
    db = load_dbc(dbc_path)
    can = sc["can"]
    fc = sc.get("faults")
    on = fc is not None and flt.faults_on(fc)
    start_ms = int(can["board_time_start_ms"])
    latency_us, frame_us = int(can["latency_us"]), int(can["frame_time_us"])
    rec = flt.FaultRecord()
    clock = flt.BoardClock(start_ms, int(can["boot_id"]), fc if on else None)
    rec.resets = clock.resets
    ev = _events(db, sensors, scans, n_imu, sc, clock, rec, sources)
    names = [m.name for m in db.messages]
    code = {name: c for c, name in enumerate(names)}
    t = np.concatenate([p[0] for p in ev.parts])
    prio = np.concatenate([np.full(len(p[0]), p[1], dtype=np.int64) for p in ev.parts])
    name = np.concatenate([np.full(len(p[0]), code[p[2]], dtype=np.int64) for p in ev.parts])
    word = np.concatenate([p[3] for p in ev.parts])
    ins = np.concatenate([p[4] for p in ev.parts])
    order = np.lexsort((ins, prio, t))  # board ms, then priority, then insertion order
    t, name, word = t[order], name[order], word[order]
    n = len(t)
    lost = rng.random(n) < float(can["loss_rate"])
    lost[0] = False  # the log starts with the first BOARD_TIME

    # host time: max(board time + latency, previous frame + one frame time) (the bus is serial)
    k = np.arange(n, dtype=np.int64)
    host = np.maximum.accumulate(EPOCH_US + (start_ms + t) * 1000 + latency_us - k * frame_us) + k * frame_us

    # an IMU sample is whole in the log when its GYRO frame and the ACCEL frame before it arrived
    is_acc, is_gyr = name == code["IMU_ACCEL"], name == code["IMU_GYRO"]
    last_acc = np.maximum.accumulate(np.where(is_acc, k, -1))
    acc_sent = np.where(last_acc >= 0, ~lost[np.maximum(last_acc, 0)], False)
    imu_samples = int(np.sum(is_gyr & ~lost & acc_sent))

    if on:
        assert fault_rng is not None, "faults need their own random stream"
        lost = flt.lost_on_bus(t, lost, fc, fault_rng, rec)
        acc_sent = np.where(last_acc >= 0, ~lost[np.maximum(last_acc, 0)], False)
        imu_samples = int(np.sum(is_gyr & ~lost & acc_sent))
    keep = ~lost
    host_kept, name_kept, word_kept = host[keep], name[keep], word[keep]
    if on:  # (implausible samples on frames that arrive: each one counted reaches the logger)
        flt.implausible(db, t[keep], name_kept, word_kept, fc, fault_rng, rec)
        n_bits = np.array([8 * m.length for m in db.messages], dtype=np.int64)[name_kept]
        flt.corrupt(word_kept, n_bits, fc, fault_rng, rec)
        (name_kept, word_kept), host_kept = flt.duplicate_and_reorder(
            (name_kept, word_kept), host_kept, frame_us, fc, fault_rng, rec
        )
    lines = _candump_lines(host_kept, name_kept, word_kept, db)
    sent = np.bincount(name[keep], minlength=len(names))
    dropped = np.bincount(name[lost], minlength=len(names))
    sent_by_name = {nm: int(sent[c]) for c, nm in enumerate(names)}
    counts = {
        "frames_total": len(lines),
        "frames_dropped": int(lost.sum()),
        "imu_samples": imu_samples,
        "mag_samples": sent_by_name["MAG"],
        "baro_samples": sent_by_name["BARO"],
        "wifi_scans": sent_by_name["WIFI_SCAN_BEGIN"],
        "wifi_ap_frames": sent_by_name["WIFI_AP"],
        "frames_by_name": {nm: v for nm, v in sent_by_name.items() if v},
        "dropped_by_name": {nm: int(dropped[c]) for c, nm in enumerate(names) if dropped[c]},
    }
    if on:  # ground truth of the faults (absent from clean runs, whose output stays as it was)
        counts["faults"] = {**rec.as_dict(), "frames_sent_by_board": n, "boot_ids": clock.boot_ids}
    return BoardOutput(lines=lines, counts=counts)
