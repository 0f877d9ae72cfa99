#!/usr/bin/env python3
"""Writes CAN test vectors for firmware/board.dbc, encoded by cantools (the reference).

Usage: gen_can_vectors.py BOARD_DBC OUTPUT_TXT

For every message: all signals zero, all at minimum, all at maximum, RANDOM_SETS seeded random
sets, and the TYPICAL sets below (values a real board sends, so that the decoder's accepting path is
certain to be covered where zeros and extremes are refused: BLE_ADV with MAC 0 or rssi >= 0). Every value lies on the signal's scaling grid (raw integer * scale + offset) and inside its
DBC range. One line per vector:

    ID_HEX DATA_HEX signal=value signal=value ...

with values printed by repr() (round-trips a double exactly). tests/c/test_can_vectors.c unpacks
each line with the C that cantools generates and compares.
"""

import math
import random
import sys

import cantools

RANDOM_SETS = 8
SEED = 20240611
# message name -> extra signal sets (physical values on the signal's grid)
TYPICAL = {
    "BLE_ADV": [{"beacon_id": 0xE078A33DB49C, "rssi": -82, "t_lo_ms": 17}],  # msindoor site1's beacon
    "LANDMARK": [{"x": -12.34, "y": 56.78, "floor": 1, "t_lo_ms": 200}],
}


def raw_limits(sig):
    """Smallest and largest raw integers whose physical value lies in [minimum, maximum]."""
    bits = sig.length
    lo_raw, hi_raw = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if sig.is_signed else (0, (1 << bits) - 1)
    lo_phys = sig.minimum if sig.minimum is not None else lo_raw * sig.scale + sig.offset
    hi_phys = sig.maximum if sig.maximum is not None else hi_raw * sig.scale + sig.offset
    lo = max(lo_raw, math.ceil((lo_phys - sig.offset) / sig.scale))
    hi = min(hi_raw, math.floor((hi_phys - sig.offset) / sig.scale))
    # Float rounding may put the grid value a hair outside the range: step inwards.
    while phys(sig, lo) < lo_phys:
        lo += 1
    while phys(sig, hi) > hi_phys:
        hi -= 1
    return lo, hi


def phys(sig, raw):
    value = raw * sig.scale + sig.offset
    return int(value) if isinstance(sig.scale, int) and isinstance(sig.offset, int) else value


def signal_sets(msg, rng):
    limits = {s.name: raw_limits(s) for s in msg.signals}
    sets = [
        {s.name: phys(s, min(max(0, limits[s.name][0]), limits[s.name][1])) for s in msg.signals},
        {s.name: phys(s, limits[s.name][0]) for s in msg.signals},
        {s.name: phys(s, limits[s.name][1]) for s in msg.signals},
    ]
    for _ in range(RANDOM_SETS):
        sets.append({s.name: phys(s, rng.randint(*limits[s.name])) for s in msg.signals})
    sets.extend(TYPICAL.get(msg.name, []))
    return sets


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    db = cantools.database.load_file(argv[1])
    rng = random.Random(SEED)
    lines = []
    unknown = set(TYPICAL) - {m.name for m in db.messages}
    if unknown:
        raise SystemExit(f"{argv[1]}: TYPICAL names messages not in the DBC: {sorted(unknown)}")
    for msg in sorted(db.messages, key=lambda m: m.frame_id):
        for signals in signal_sets(msg, rng):
            data = db.encode_message(msg.name, signals)  # strict: raises if a value is out of range
            assert len(data) == msg.length
            decoded = db.decode_message(msg.frame_id, data, decode_choices=False)
            for name, value in signals.items():
                step = msg.get_signal_by_name(name).scale
                assert abs(decoded[name] - value) <= step / 2, (msg.name, name, value, decoded[name])
            fields = " ".join(f"{name}={value!r}" for name, value in signals.items())
            lines.append(f"{msg.frame_id:03X} {data.hex().upper()} {fields}")
    with open(argv[2], "w", encoding="ascii") as out:
        out.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
