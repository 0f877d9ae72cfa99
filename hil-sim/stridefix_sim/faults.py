"""Bus and board faults of the board emulator (scenario table ``[faults]``), with their ground truth.

Two kinds, applied at two places of ``board.py``:

* board faults change what the board sends. A reset (``reset_at_s``) stops the board for
  ``reset_down_ms`` (nothing is sent), then it boots again as a real board does: a new boot_id
  (``can.boot_id`` + the number of resets so far, mod 256), BOARD_TIME first, board time restarting
  at ``reset_time_start_ms``, every seq counter and the scan_id at 0 (:class:`BoardClock`). A Wi-Fi
  scan that a reset interrupts is never sent. An implausible sample (``implausible_at_s``,
  ``implausible_rate``) is one IMU frame whose ``implausible_signal`` is wrong: its sign bit flipped
  (``bitflip``: one bit, accel_z 9.8 → −147 m/s², inside the int16 range) or set to full scale.
* bus faults change what the logger receives of what the board sent: loss bursts (``burst_rate``
  per frame, ``burst_frames`` long), silence windows (``silence_at_s``, ``silence_s``: no frame
  arrives), payload corruption (``corrupt_rate``: ``corrupt_bits`` distinct random bits of the
  payload flipped), duplicates (``duplicate_rate``: the frame arrives twice) and reordering
  (``reorder_rate``: the frame arrives after the next ``reorder_frames`` frames; arrival times stay
  in order, the payloads move).

Every fault draws from its own random stream (``pipeline.simulate``) and only when it is on: with
every fault off nothing here draws a number or changes a byte, so clean runs are byte-identical to a
simulator without this module. :class:`FaultRecord` counts what was damaged, per kind (the ground
truth a harness compares with what the logger counted).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

# IMU signals an implausible sample can hit, by message
IMPLAUSIBLE_SIGNALS = {
    "accel_x": "IMU_ACCEL",
    "accel_y": "IMU_ACCEL",
    "accel_z": "IMU_ACCEL",
    "gyro_x": "IMU_GYRO",
    "gyro_y": "IMU_GYRO",
    "gyro_z": "IMU_GYRO",
}
IMPLAUSIBLE_MODES = ("bitflip", "full_scale")


def faults_on(f: dict) -> bool:
    """Whether any fault of the ``[faults]`` table is on."""
    return bool(
        f["burst_rate"] > 0
        or f["duplicate_rate"] > 0
        or f["reorder_rate"] > 0
        or f["corrupt_rate"] > 0
        or f["implausible_rate"] > 0
        or f["silence_at_s"]
        or f["reset_at_s"]
        or f["implausible_at_s"]
    )


@dataclasses.dataclass
class FaultRecord:
    """Frames the faults damaged, per kind. ``lost_random`` is ``can.loss_rate``'s loss; a frame lost
    to two causes counts once, in the first of random, burst, silence."""

    resets: int = 0
    unsent_reset: int = 0  # frames the board did not send while it rebooted
    scans_lost_reset: int = 0  # Wi-Fi scans a reset interrupted (none of their frames is sent)
    implausible: int = 0
    lost_random: int = 0
    lost_burst: int = 0
    lost_silence: int = 0
    corrupted: int = 0
    duplicated: int = 0  # extra copies received
    reordered: int = 0  # frames received late

    @property
    def frames_lost(self) -> int:
        return self.lost_random + self.lost_burst + self.lost_silence

    @property
    def frames_affected(self) -> int:
        """Frames the faults changed: lost, unsent, implausible, corrupted, duplicated or moved."""
        return (
            self.frames_lost
            + self.unsent_reset
            + self.implausible
            + self.corrupted
            + self.duplicated
            + self.reordered
        )

    def as_dict(self) -> dict:
        return {
            **dataclasses.asdict(self),
            "frames_lost": self.frames_lost,
            "frames_affected": self.frames_affected,
        }


class BoardClock:
    """Board time, boot id and counter restarts of a board that resets at ``reset_at_s``.

    Boot k runs from ``seg_start_ms[k]`` (simulated ms since the start; 0 for the first boot) to the
    next reset; the board sends nothing from a reset until ``reset_down_ms`` later. Without resets
    every method reduces to the plain formulas (board ms = start + t mod 2**32, seq = index mod 256)."""

    def __init__(self, start_ms: int, boot_id: int, faults: dict | None = None):
        resets = sorted(float(s) for s in faults["reset_at_s"]) if faults else []
        down_ms = int(faults["reset_down_ms"]) if faults else 0
        reset_ms = np.array([round(s * 1000) for s in resets], dtype=np.int64)
        self.end_ms = np.concatenate([reset_ms, [np.iinfo(np.int64).max]])  # each boot's end
        self.seg_start_ms = np.concatenate([[0], reset_ms + down_ms]).astype(np.int64)
        after = int(faults["reset_time_start_ms"]) if faults else 0
        self.time0_ms = np.array([start_ms] + [after] * len(resets), dtype=np.int64)
        self.boot_ids = [(boot_id + k) % 256 for k in range(len(resets) + 1)]
        self.resets = len(resets)

    def segment(self, t_ms: np.ndarray) -> np.ndarray:
        """Boot index of each simulated time [ms]; −1 while the board reboots (nothing is sent)."""
        t = np.asarray(t_ms, dtype=np.int64)
        k = np.searchsorted(self.seg_start_ms, t, side="right") - 1
        return np.where(t < self.end_ms[k], k, -1)

    def board_ms(self, t_ms: np.ndarray, seg: np.ndarray | None = None) -> np.ndarray:
        """The uint32 board time of each simulated time (of a sending boot)."""
        t = np.asarray(t_ms, dtype=np.int64)
        k = np.maximum(self.segment(t) if seg is None else seg, 0)
        return (self.time0_ms[k] + t - self.seg_start_ms[k]) % 2**32

    def counter(self, seg: np.ndarray) -> np.ndarray:
        """Per-boot running count (0, 1, ... restarting at each boot) of events in time order."""
        i = np.arange(len(seg), dtype=np.int64)
        if self.resets == 0:
            return i
        first = np.searchsorted(seg, np.arange(len(self.boot_ids)), side="left")
        return i - first[np.maximum(seg, 0)]

    def periodic(self, offset_ms: int, period_ms: int, duration_ms: int) -> tuple[np.ndarray, np.ndarray]:
        """Times [ms] and boot index of a frame sent every ``period_ms`` from ``offset_ms`` after each
        boot, up to ``duration_ms``."""
        if self.resets == 0:
            return np.arange(offset_ms, duration_ms + 1, period_ms, dtype=np.int64), np.zeros(0, np.int64)
        ts, segs = [], []
        for k, t0 in enumerate(self.seg_start_ms.tolist()):
            t = np.arange(t0 + offset_ms, min(duration_ms, self.end_ms[k] - 1) + 1, period_ms, dtype=np.int64)
            ts.append(t)
            segs.append(np.full(len(t), k, dtype=np.int64))
        return np.concatenate(ts), np.concatenate(segs)


def implausible(
    db, t_ms: np.ndarray, code: np.ndarray, word: np.ndarray, f: dict, rng, rec: FaultRecord
) -> None:
    """Makes the chosen IMU frames implausible in place (``word``): the first frame of
    ``implausible_signal``'s message at or after each ``implausible_at_s``, plus each such frame with
    probability ``implausible_rate``."""
    if not (f["implausible_at_s"] or f["implausible_rate"] > 0):
        return
    sig_name = f["implausible_signal"]
    msg = db.get_message_by_name(IMPLAUSIBLE_SIGNALS[sig_name])
    sig = msg.get_signal_by_name(sig_name)
    idx = np.flatnonzero(code == db.messages.index(msg))
    chosen = set()
    for at_s in f["implausible_at_s"]:
        j = np.searchsorted(t_ms[idx], round(float(at_s) * 1000), side="left")
        if j < len(idx):
            chosen.add(int(idx[j]))
    if f["implausible_rate"] > 0:
        chosen.update(idx[rng.random(len(idx)) < f["implausible_rate"]].tolist())
    sel = np.array(sorted(chosen), dtype=np.int64)
    shift = np.uint64(sig.start)
    if f["implausible_mode"] == "bitflip":
        word[sel] ^= np.uint64(1) << np.uint64(sig.start + sig.length - 1)
    else:  # full_scale: the largest raw value the signal can carry
        mask = np.uint64((1 << sig.length) - 1) << shift
        raw = np.uint64(round((sig.maximum - sig.offset) / sig.scale)) << shift
        word[sel] = (word[sel] & ~mask) | (raw & mask)
    rec.implausible += len(sel)


def lost_on_bus(t_ms: np.ndarray, lost: np.ndarray, f: dict, rng, rec: FaultRecord) -> np.ndarray:
    """``lost`` (the random loss) plus loss bursts and silence windows; the first frame stays."""
    n = len(t_ms)
    out = lost.copy()
    rec.lost_random = int(lost.sum())
    if f["burst_rate"] > 0:
        starts = np.flatnonzero(rng.random(n) < f["burst_rate"])
        d = np.zeros(n + 1, dtype=np.int64)
        np.add.at(d, starts, 1)
        np.add.at(d, np.minimum(starts + int(f["burst_frames"]), n), -1)
        burst = np.cumsum(d[:n]) > 0
        burst[0] = False
        rec.lost_burst = int(np.sum(burst & ~out))
        out |= burst
    if f["silence_at_s"]:
        quiet = np.zeros(n, dtype=bool)
        for at_s in f["silence_at_s"]:
            t0 = round(float(at_s) * 1000)
            quiet |= (t_ms >= t0) & (t_ms < t0 + round(float(f["silence_s"]) * 1000))
        quiet[0] = False
        rec.lost_silence = int(np.sum(quiet & ~out))
        out |= quiet
    return out


def corrupt(word: np.ndarray, n_bits: np.ndarray, f: dict, rng, rec: FaultRecord) -> None:
    """Flips ``corrupt_bits`` distinct random payload bits (of each frame's ``n_bits``) in place."""
    if f["corrupt_rate"] <= 0:
        return
    sel = np.flatnonzero(rng.random(len(word)) < f["corrupt_rate"])
    if not len(sel):
        return
    keys = rng.random((len(sel), 64))
    keys[np.arange(64)[None, :] >= n_bits[sel][:, None]] = np.inf  # only bits inside the payload
    bits = np.argsort(keys, axis=1)[:, : int(f["corrupt_bits"])].astype(np.uint64)
    flips = np.bitwise_or.reduce(np.uint64(1) << bits, axis=1)
    word[sel] ^= flips
    rec.corrupted = len(sel)


def duplicate_and_reorder(
    arrays: Sequence[np.ndarray], host_us: np.ndarray, frame_us: int, f: dict, rng, rec: FaultRecord
) -> tuple[list[np.ndarray], np.ndarray]:
    """Duplicates (a copy one frame time after the original) and reordering (a frame's content moved
    behind the next ``reorder_frames`` frames; arrival times keep their order) of the received
    frames; ``arrays`` are the per-frame columns that move together (e.g. id and payload)."""
    cols = list(arrays)
    host = host_us
    if f["duplicate_rate"] > 0:
        twice = rng.random(len(host)) < f["duplicate_rate"]
        rep = 1 + twice.astype(np.int64)
        cols = [np.repeat(c, rep) for c in cols]
        src = np.repeat(np.arange(len(host)), rep)
        copy = np.concatenate([[False], src[1:] == src[:-1]])
        host = np.repeat(host, rep) + np.where(copy, frame_us, 0)
        host = np.maximum.accumulate(host)
        rec.duplicated = int(twice.sum())
    if f["reorder_rate"] > 0:
        m, k = len(host), int(f["reorder_frames"])
        perm = np.arange(m)
        busy_until = -1
        for i in np.flatnonzero(rng.random(m) < f["reorder_rate"]).tolist():
            j = min(i + k, m - 1)
            if i <= busy_until or j == i:
                continue  # overlapping moves would be one larger move
            perm[i:j] = np.arange(i + 1, j + 1)
            perm[j] = i
            busy_until = j
            rec.reordered += 1
        cols = [c[perm] for c in cols]
    return cols, host
