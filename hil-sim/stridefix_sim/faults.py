"""Bus and board faults of the board emulator (scenario table ``[faults]``), with their ground truth.

Two kinds, applied at two places of ``board.py``:

* board faults change what the board sends. A reset (``reset_at_s``) stops the board for
  ``reset_down_ms`` (nothing is sent), then it boots again as a real board does: a new boot_id
  (``can.boot_id`` + the number of resets so far, mod 256), BOARD_TIME first, board time restarting
  at ``reset_time_start_ms``, every seq counter and the scan_id at 0 (:class:`BoardClock`). A Wi-Fi
  scan that a reset interrupts is never sent. An implausible sample (``implausible_at_s``,
  ``implausible_rate``) is one IMU frame whose ``implausible_signal`` is wrong: its sign bit flipped
  (``bitflip``: one bit, accel_z 9.8 → −147 m/s², inside the int16 range) or set to full scale.
  A stuck board clock (``board_time_stuck_at_s``, ``board_time_stuck_s``): for that long every
  BOARD_TIME carries the board time of the window's start (same boot id) while the samples' seq and
  t_lo go on. A failed IMU (``imu_failed_at_s``, ``imu_failed_s``): for that long every IMU_ACCEL and
  IMU_GYRO signal reads full scale, the largest raw value the DBC gives it (the signals are integers:
  NaN or inf cannot be sent, a saturated or disconnected sensor reads its rail), seq and t_lo go on.
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
WINDOW_MAX_S = 86_400  # the longest fault window [s] (a day: "until the walk ends")


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
        or f["board_time_stuck_at_s"]
        or f["imu_failed_at_s"]
    )


def validate(f: dict, check) -> None:
    """Checks the ``[faults]`` table; ``check(ok, key, message)`` reports a bad value by its key."""
    for key in ("burst_rate", "duplicate_rate", "reorder_rate", "corrupt_rate", "implausible_rate"):
        check(0 <= f[key] < 1, f"faults.{key}", "must be in 0..1")
    check(1 <= f["burst_frames"] <= 10_000, "faults.burst_frames", "must be in 1..10000")
    check(1 <= f["reorder_frames"] <= 100, "faults.reorder_frames", "must be in 1..100")
    check(1 <= f["corrupt_bits"] <= 64, "faults.corrupt_bits", "must be in 1..64")
    check(0 < f["silence_s"] <= 3600, "faults.silence_s", "must be in 0..3600 (> 0)")
    for key in ("board_time_stuck_s", "imu_failed_s"):
        check(0 < f[key] <= WINDOW_MAX_S, f"faults.{key}", f"must be in 0..{WINDOW_MAX_S} (> 0)")
    check(0 <= f["reset_down_ms"] <= 60_000, "faults.reset_down_ms", "must be in 0..60000")
    check(0 <= f["reset_time_start_ms"] < 2**32, "faults.reset_time_start_ms", "must be in 0..2**32-1")
    for key in ("silence_at_s", "reset_at_s", "implausible_at_s", "board_time_stuck_at_s", "imu_failed_at_s"):
        check(all(v >= 0 for v in f[key]), f"faults.{key}", "must hold times >= 0")
    resets = sorted(f["reset_at_s"])
    check(
        all(b - a > f["reset_down_ms"] / 1000 for a, b in zip(resets, resets[1:])),
        "faults.reset_at_s",
        "must be further apart than faults.reset_down_ms",
    )
    check(
        f["implausible_signal"] in IMPLAUSIBLE_SIGNALS,
        "faults.implausible_signal",
        f"must be one of {', '.join(IMPLAUSIBLE_SIGNALS)}",
    )
    check(
        f["implausible_mode"] in IMPLAUSIBLE_MODES,
        "faults.implausible_mode",
        f"must be one of {', '.join(IMPLAUSIBLE_MODES)}",
    )


def windows(t_ms: np.ndarray, starts_s: Sequence[float], length_s: float) -> np.ndarray:
    """Whether each simulated time [ms] lies in one of the windows [start, start + length)."""
    t = np.asarray(t_ms, dtype=np.int64)
    inside = np.zeros(len(t), dtype=bool)
    for at_s in starts_s:
        t0 = round(float(at_s) * 1000)
        inside |= (t >= t0) & (t < t0 + round(float(length_s) * 1000))
    return inside


@dataclasses.dataclass
class FaultRecord:
    """Frames the faults damaged, per kind. ``lost_random`` is ``can.loss_rate``'s loss; a frame lost
    to two causes counts once, in the first of random, burst, silence."""

    resets: int = 0
    unsent_reset: int = 0  # frames the board did not send while it rebooted
    scans_lost_reset: int = 0  # Wi-Fi scans a reset interrupted (none of their frames is sent)
    implausible: int = 0
    board_time_stuck: int = 0  # BOARD_TIME frames sent with a stale time
    imu_failed: int = 0  # IMU_ACCEL and IMU_GYRO frames sent at full scale
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
            + self.board_time_stuck
            + self.imu_failed
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


def board_time_sent(clock: BoardClock, t_ms: np.ndarray, f: dict | None, rec: FaultRecord) -> np.ndarray:
    """The uint32 time_ms of each BOARD_TIME sent at simulated ``t_ms``: the board time, but inside a
    ``board_time_stuck_at_s`` window the board time of the window's start (the stale value repeats
    while the boot that was running at the start goes on)."""
    t = np.asarray(t_ms, dtype=np.int64)
    seg = clock.segment(t)
    sent = clock.board_ms(t, seg)
    if not f or not f["board_time_stuck_at_s"]:
        return sent
    true = sent.copy()
    for at_s in f["board_time_stuck_at_s"]:
        t0 = np.array([round(float(at_s) * 1000)], dtype=np.int64)
        seg0 = clock.segment(t0)
        inside = windows(t, [at_s], f["board_time_stuck_s"]) & (seg == seg0[0])
        sent = np.where(inside, clock.board_ms(t0, seg0)[0], sent)
    rec.board_time_stuck += int(np.sum(sent != true))
    return sent


def imu_failed(
    db, t_ms: np.ndarray, acc: np.ndarray, gyr: np.ndarray, f: dict | None, rec: FaultRecord
) -> None:
    """Sets the IMU samples (rows of ``acc`` [m/s²] and ``gyr`` [deg/s], taken at simulated ``t_ms``)
    inside an ``imu_failed_at_s`` window to full scale in place: each axis at its signal's maximum,
    which the board encodes as the largest raw value."""
    if not f or not f["imu_failed_at_s"]:
        return
    bad = windows(t_ms, f["imu_failed_at_s"], f["imu_failed_s"])
    for values, msg_name, prefix in ((acc, "IMU_ACCEL", "accel"), (gyr, "IMU_GYRO", "gyro")):
        msg = db.get_message_by_name(msg_name)
        for axis, name in enumerate("xyz"):
            values[bad, axis] = msg.get_signal_by_name(f"{prefix}_{name}").maximum
    rec.imu_failed += 2 * int(bad.sum())  # an ACCEL and a GYRO frame per sample


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
        quiet = windows(t_ms, f["silence_at_s"], f["silence_s"])
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
