"""Writes the seed corpus of the fuzz harnesses (tests/fuzz/corpus/<harness>/) from real inputs.

The seeds are committed; this script says where they came from and rewrites them after a format change:

    .venv/bin/stridefix sim --out /tmp/sim
    .venv/bin/python tests/fuzz/seed_corpus.py --stridefixd build/firmware/stridefixd \\
        --candump /tmp/sim/board.candump --site-vectors build/tests/site_vectors --out tests/fuzz/corpus

- candump: the first lines of a SIL walk and the lines of its first Wi-Fi scan, and those scan lines
  as can-utils' asc2log writes them (a direction flag on each) with CAN FD lines among them;
- board_rx: the same frames in fuzz_board_rx.c's 12-byte records;
- lcm_input: the raw-sensor LCM log stridefixd writes for the walk's first seconds (IMU, MAG, BARO,
  WIFI, a few non-sensor events), with one GNSS event added (the SIL walk has none);
- site: the site-file test vector and seven of its variants (two of them version-2 rules, two
  version-3 rules);
- config: `stridefixd --print-config`.
"""

from __future__ import annotations

import argparse
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

EVENTLOG_MAGIC = 0xEDA1DA01
# fuzz_board_rx.c's dbc_ids, in its order: a record's first byte selects one of these.
DBC_IDS = [0x080, 0x100, 0x101, 0x110, 0x120, 0x200, 0x201, 0x202, 0x300, 0x301, 0x7F0]
SENSOR_CHANNELS = {"IMU", "MAG", "BARO", "WIFI", "GNSS"}
CANDUMP_LINES = 300
LOG_EVENTS = 200


def parse_candump(line: str) -> tuple[int, int, bytes]:
    """(t_us, id, data) of one `candump -L` data frame line."""
    stamp, _iface, frame = line.split()
    can_id, data = frame.split("#")
    return round(float(stamp.strip("()")) * 1e6), int(can_id, 16), bytes.fromhex(data)


def asc2log_lines(lines: list[str]) -> bytes:
    """The lines with asc2log's direction flag (" R", every fifth " T") and, after every tenth, a CAN
    FD line (candump -L ``id##<flags><data>``) of 3, 12 or 64 bytes at the same time."""
    out = []
    for i, line in enumerate(lines):
        stamp, iface, _frame = line.split()
        out.append(f"{line.rstrip()} {'T' if i % 5 == 4 else 'R'}\n")
        if i % 10 == 9:
            n = (3, 12, 64)[i // 10 % 3]
            out.append(f"{stamp} {iface} 3{i:02X}##{i % 16:X}{bytes(range(n)).hex().upper()}\n")
    return "".join(out).encode()


def board_rx_records(lines: list[str]) -> bytes:
    """The frames as fuzz_board_rx.c reads them: selector, dlc, host time step [µs], 8 data bytes."""
    out = bytearray()
    last_t_us = None
    for line in lines:
        t_us, can_id, data = parse_candump(line)
        step_us = 0 if last_t_us is None else min(max(t_us - last_t_us, 0), 0xFFFF)
        last_t_us = t_us
        out += struct.pack(">BBH", DBC_IDS.index(can_id), len(data), step_us) + data.ljust(8, b"\0")
    return bytes(out)


def read_events(path: Path) -> list[tuple[int, int, str, bytes]]:
    """(number, timestamp_us, channel, data) of every event of an LCM log."""
    raw = path.read_bytes()
    events, pos = [], 0
    while pos < len(raw):
        magic, number, t_us, n_channel, n_data = struct.unpack_from(">IqqiI", raw, pos)
        if magic != EVENTLOG_MAGIC:
            raise ValueError(f"{path}: offset {pos}: bad magic 0x{magic:08x}")
        pos += 28
        channel = raw[pos : pos + n_channel].decode()
        events.append((number, t_us, channel, raw[pos + n_channel : pos + n_channel + n_data]))
        pos += n_channel + n_data
    return events


def write_events(events: list[tuple[int, int, str, bytes]]) -> bytes:
    out = bytearray()
    for number, t_us, channel, data in events:
        name = channel.encode()
        out += struct.pack(">IqqiI", EVENTLOG_MAGIC, number, t_us, len(name), len(data)) + name + data
    return bytes(out)


def lcm_log_seed(stridefixd: str, lines: list[str], lcmtypes_python: Path) -> bytes:
    sys.path.insert(0, str(lcmtypes_python))
    from stridefix import gnss_t  # noqa: PLC0415 (generated bindings: importable only after the build)

    with tempfile.TemporaryDirectory() as tmp:
        candump = Path(tmp, "walk.candump")
        candump.write_text("".join(lines))
        log = Path(tmp, "run.lcmlog")
        subprocess.run([stridefixd, "--input", str(candump), "--log", str(log), "--quiet"], check=True)
        events = read_events(log)
    sensor = [e for e in events if e[2] in SENSOR_CHANNELS][:LOG_EVENTS]
    other = [e for e in events if e[2] not in SENSOR_CHANNELS][:5]
    fix = gnss_t()
    fix.t_us, fix.lat_deg, fix.lon_deg, fix.alt_m, fix.accuracy_m = sensor[-1][1], 48.1, 11.5, 520.0, 4.0
    kept = sorted(sensor + other, key=lambda e: e[0])
    kept.append((kept[-1][0] + 1, kept[-1][1], "GNSS", fix.encode()))
    return write_events(kept)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stridefixd", required=True)
    ap.add_argument("--candump", type=Path, required=True, help="a SIL walk's board.candump")
    ap.add_argument("--site-vectors", type=Path, required=True, help="build/tests/site_vectors")
    ap.add_argument("--lcmtypes-python", type=Path, default=Path("build/lcmtypes/python"))
    ap.add_argument("--out", type=Path, required=True, help="tests/fuzz/corpus")
    args = ap.parse_args()

    with args.candump.open() as f:
        lines = [next(f) for _ in range(3000)]
    start = lines[:CANDUMP_LINES]
    scan = [ln for ln in lines if parse_candump(ln)[1] in (0x080, 0x200, 0x201, 0x202)][:40]
    seeds = {
        "candump/walk_start.candump": "".join(start).encode(),
        "candump/walk_scan.candump": "".join(scan).encode(),
        "candump/asc2log_scan.candump": asc2log_lines(scan),
        "board_rx/walk_start.frames": board_rx_records(start),
        "board_rx/walk_scan.frames": board_rx_records(scan),
        "lcm_input/walk_start.lcmlog": lcm_log_seed(args.stridefixd, lines, args.lcmtypes_python),
        "config/print_config.ini": subprocess.run(
            [args.stridefixd, "--print-config"], check=True, capture_output=True
        ).stdout,
    }
    for name, data in seeds.items():
        path = args.out / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    (args.out / "site").mkdir(parents=True, exist_ok=True)
    shutil.copy(args.site_vectors / "site.sfsite", args.out / "site" / "site.sfsite")
    for variant in (
        "ap_index",
        "bssid_order",
        "count_zero",
        "wall_floor",
        "beacon_order",
        "outline_not_consecutive",
        "context_duplicate",
    ):
        shutil.copy(
            args.site_vectors / "variants" / f"{variant}.sfsite", args.out / "site" / f"{variant}.sfsite"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
