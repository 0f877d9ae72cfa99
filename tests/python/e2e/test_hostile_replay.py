"""stridefixd --replay on hostile raw-sensor logs: a WIFI event declaring 2^29 readings died
with SIGSEGV in the generated LCM decode, and an event header claiming 1.9 GB made liblcm map 1.9 GB and
then end the replay silently with status 0.

GIVEN a log of good IMU events around one bad event, WHEN it is replayed, THEN the bad event is named
(event number, offset, field) and counted, the good events before it are used, and the exit status says
whether the rest of the log could be trusted (0) or was refused (1)."""

from __future__ import annotations

import struct
import subprocess
from pathlib import Path

import pytest
from stridefix import imu_t, wifi_scan_t

MAGIC = 0xEDA1DA01


def _event(
    number: int, channel: str, data: bytes, *, magic: int = MAGIC, data_len: int | None = None
) -> bytes:
    name = channel.encode()
    n = len(data) if data_len is None else data_len
    return struct.pack(">IqqiI", magic, number, 1000 * number, len(name), n) + name + data


def _imu(seq: int) -> bytes:
    m = imu_t()
    m.t_us, m.seq, m.accel_mps2, m.gyro_radps = 10_000 * seq, seq, [0.0, 0.0, 9.81], [0.0, 0.0, 0.0]
    return m.encode()


def _wifi_claiming(n_ap: int) -> bytes:
    m = wifi_scan_t()
    m.t_us, m.scan_id, m.complete, m.n_ap = 1, 2, True, 1
    m.bssid, m.rssi_dbm, m.freq_mhz = [0x0123456789AB], [-60.0], [2412]
    raw = bytearray(m.encode())
    raw[25:29] = struct.pack(">i", n_ap)  # after the hash, t_us, scan_id and complete
    return bytes(raw)


def _replay(stridefixd: Path, log: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(stridefixd), "--replay", str(log), "--no-log"], capture_output=True, text=True, timeout=60
    )


@pytest.mark.parametrize(
    ("bad", "status", "words"),
    [
        (_event(3, "WIFI", _wifi_claiming(1 << 29)), 0, "(WIFI): payload: n_ap = 536870912 needs"),
        (_event(3, "WIFI", _wifi_claiming(-7)), 0, "n_ap = -7 is negative"),
        (_event(3, "IMU", b"\0" * 16, data_len=1_900_000_000), 0, "log ends inside the data (truncated"),
        (_event(3, "IMU", _imu(3), magic=0xDEADBEEF), 1, "bad magic 0xDEADBEEF"),
        # a message of another type on a channel: said so (its type fingerprint), before any of its
        # fields is read as the channel's type would have them (an IMU sample on WIFI was a "bad n_ap")
        (_event(3, "WIFI", _imu(3)), 0, "(WIFI): payload is a stridefix.imu_t, not a stridefix.wifi_scan_t"),
        (
            _event(3, "IMU", _wifi_claiming(1)),
            0,
            "(IMU): payload is a stridefix.wifi_scan_t, not a stridefix.imu_t",
        ),
        (_event(3, "BLE", b"\x01" * 40), 0, "(BLE): payload is not a stridefix.ble_scan_t (type fingerprint"),
    ],
    ids=[
        "wifi-2^29",
        "wifi-negative",
        "header-1.9GB",
        "bad-magic",
        "imu-on-wifi",
        "wifi-on-imu",
        "junk-on-ble",
    ],
)
def test_bad_event_is_named_and_counted(stridefixd, tmp_path, bad, status, words):
    log = tmp_path / "hostile.lcmlog"
    log.write_bytes(b"".join(_event(i, "IMU", _imu(i)) for i in range(3)) + bad)
    proc = _replay(stridefixd, log)
    assert proc.returncode == status, proc.stderr
    assert f"hostile.lcmlog: event 3 at offset {3 * len(_event(0, 'IMU', _imu(0)))}" in proc.stderr
    assert words in proc.stderr
    assert "1 decode errors" in proc.stderr
    assert "3 IMU" in proc.stderr
