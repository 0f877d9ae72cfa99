"""The one LCM writer of the data sets: a :class:`~.rawwalk.RawWalk` → a raw-sensor LCM event log.

``stridefixd --input lcmlog:FILE`` (or ``--replay FILE``) replays what this writes:

=======  ===========  ==============================================================================
channel  type         from
=======  ===========  ==============================================================================
IMU      imu_t        ``imu``: t_us, seq = row (0, 1, ... in time order), accel, gyro
MAG      mag_t        ``mag``: t_us, seq = row, field
BARO     baro_t       ``baro``: t_us, seq = row, pressure; temperature NaN (no data set has it)
GNSS     gnss_t       ``gnss``: t_us, latitude, longitude, altitude, accuracy
WIFI     wifi_scan_t  one message per scan of ``wifi``: scan_id = scan index, complete, its APs
BLE      ble_scan_t   one message per window of ``ble``: t_us, its beacons' ids and RSSIs
TRUTH    truth_t      ``truth``: t_us, x, y, floor; heading NaN, step_count −1, SOURCE_WAYPOINT
=======  ===========  ==============================================================================

The LCM event timestamp is the message's ``t_us``; events are written in time order, ties broken by
channel in the order of the table above, then by row. A stream without rows writes nothing.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import numpy as np

from stridefix_analyzer.datasets.rawwalk import RawWalk

#: Channels, also the tie-break order of equal times.
CHANNELS = ("IMU", "MAG", "BARO", "GNSS", "WIFI", "BLE", "TRUTH")


class _Encodable(Protocol):
    def encode(self) -> bytes: ...


def _makers(raw: RawWalk) -> tuple[Callable[[int], _Encodable], ...]:
    """One message builder per channel of :data:`CHANNELS`: row index → LCM message."""
    from stridefix import baro_t, ble_scan_t, gnss_t, imu_t, mag_t, truth_t, wifi_scan_t

    imu, mag, baro, gnss, truth = raw.imu, raw.mag, raw.baro, raw.gnss, raw.truth
    wifi, bounds = raw.wifi, raw.scan_bounds()
    ble, ble_bounds = raw.ble, raw.ble_bounds()

    def imu_msg(i: int) -> _Encodable:
        m = imu_t()
        m.t_us, m.seq = int(imu["t_us"][i]), i
        m.accel_mps2 = imu["accel_mps2"][i].tolist()
        m.gyro_radps = imu["gyro_radps"][i].tolist()
        return m  # type: ignore[no-any-return]

    def mag_msg(i: int) -> _Encodable:
        m = mag_t()
        m.t_us, m.seq = int(mag["t_us"][i]), i
        m.field_ut = mag["field_ut"][i].tolist()
        return m  # type: ignore[no-any-return]

    def baro_msg(i: int) -> _Encodable:
        m = baro_t()
        m.t_us, m.seq = int(baro["t_us"][i]), i
        m.pressure_pa, m.temperature_degc = float(baro["pressure_pa"][i]), float("nan")
        return m  # type: ignore[no-any-return]

    def gnss_msg(i: int) -> _Encodable:
        m = gnss_t()
        m.t_us = int(gnss["t_us"][i])
        m.lat_deg, m.lon_deg = float(gnss["lat_deg"][i]), float(gnss["lon_deg"][i])
        m.alt_m, m.accuracy_m = float(gnss["alt_m"][i]), float(gnss["accuracy_m"][i])
        return m  # type: ignore[no-any-return]

    def wifi_msg(i: int) -> _Encodable:
        rows = slice(int(bounds[i]), int(bounds[i + 1]))
        m = wifi_scan_t()
        m.t_us, m.scan_id, m.complete = int(wifi["t_us"][rows.start]), i, True
        m.n_ap = rows.stop - rows.start
        m.bssid = wifi["bssid"][rows].tolist()
        m.rssi_dbm = wifi["rssi_dbm"][rows].tolist()
        m.freq_mhz = wifi["freq_mhz"][rows].tolist()
        return m  # type: ignore[no-any-return]

    def ble_msg(i: int) -> _Encodable:
        rows = slice(int(ble_bounds[i]), int(ble_bounds[i + 1]))
        m = ble_scan_t()
        m.t_us, m.n = int(ble["t_us"][rows.start]), rows.stop - rows.start
        m.beacon_id = ble["beacon_id"][rows].tolist()
        m.rssi_dbm = ble["rssi_dbm"][rows].tolist()
        return m  # type: ignore[no-any-return]

    def truth_msg(i: int) -> _Encodable:
        m = truth_t()
        m.t_us = int(truth["t_us"][i])
        m.x_m, m.y_m = float(truth["x_m"][i]), float(truth["y_m"][i])
        m.floor, m.heading_rad, m.step_count = int(truth["floor"][i]), float("nan"), -1
        m.source = truth_t.SOURCE_WAYPOINT
        return m  # type: ignore[no-any-return]

    return imu_msg, mag_msg, baro_msg, gnss_msg, wifi_msg, ble_msg, truth_msg


def write_lcmlog(raw: RawWalk, out_path: str | os.PathLike[str]) -> int:
    """Write ``raw`` as an LCM event log (overwriting ``out_path``); returns the events written.

    The log is written as ``out_path.part`` and renamed when whole; on any failure the part is removed
    and ``out_path`` is left as it was.

    Raises
    ------
    OSError
        The log cannot be written.
    """
    import lcm

    out = os.fspath(out_path)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    times = [raw.imu["t_us"], raw.mag["t_us"], raw.baro["t_us"], raw.gnss["t_us"]]
    times += [raw.scan_t_us(), raw.ble_t_us(), raw.truth["t_us"]]
    times = [np.asarray(t, dtype=np.int64) for t in times]
    t_all = np.concatenate(times)
    rank = np.concatenate([np.full(len(t), r) for r, t in enumerate(times)])
    index = np.concatenate([np.arange(len(t)) for t in times])
    order = np.lexsort((index, rank, t_all))
    makers = _makers(raw)
    part = out + ".part"  # the log appears under its name whole, or not at all
    log = lcm.EventLog(part, "w", overwrite=True)
    try:
        try:
            for r, i, t in zip(rank[order].tolist(), index[order].tolist(), t_all[order].tolist()):
                log.write_event(t, CHANNELS[r], makers[r](i).encode())
        finally:
            log.close()
        os.replace(part, out)
    except BaseException:
        Path(part).unlink(missing_ok=True)
        raise
    return len(order)
