"""Read StrideFix LCM event logs into named numpy columns.

The loader end of the analyzer's one container: :func:`read_logs` turns one or more LCM event logs
(``lcm.EventLog`` format, e.g. the firmware's log plus the simulator's separate truth log) into a
:class:`LogData`, whose per-channel :class:`Table` objects are dicts of equal-length numpy columns with
units in their names (``t_us``, ``x_m``, ``heading_rad``). Metrics and reports only ever see these.

Channels and their columns (time ``t_us`` is the message's own board time [µs], not the log's
receive time; every table is sorted by ``t_us``, stably, so messages with equal times keep log order):

========  ==========================================================================================
IMU       t_us, seq, accel_{x,y,z}_mps2, gyro_{x,y,z}_radps
MAG       t_us, seq, field_{x,y,z}_ut
BARO      t_us, seq, pressure_pa, temperature_degc
WIFI      t_us, scan_id, complete, n_ap   (per scan; the APs are in the WIFI_AP table)
WIFI_AP   scan_row (row in WIFI), bssid, rssi_dbm, freq_mhz
GNSS      t_us, lat_deg, lon_deg, alt_m, accuracy_m
STEP      t_us, index, length_m, accel_range_mps2, period_s, heading_rad, activity, floor
FIX       t_us, method, x_m, y_m, floor, accuracy_m, n_ap_used, innovation_{x,y}_m,
          innovation_var_m2, test_ratio, alpha, accuracy_factor, drift, accepted, reason, reason_text
POSE      t_us, x_m, y_m, floor, heading_rad, sigma_m, step_count, scheme
TRUTH     t_us, x_m, y_m, floor, heading_rad, step_count, source
HEALTH    every health_t field (counters over time); the last report is also in ``LogData.health``
========  ==========================================================================================

``CONFIG`` becomes the ``LogData.config`` key → value dict (plus ``LogData.versions``).

Errors: a missing or unreadable file raises :class:`LogReadError` naming it. Bad data is not an
error: unknown channels and messages that fail to decode are counted (by channel), and a log cut
short reads up to its last whole record, with a warning in ``LogData.warnings``.
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from typing import Callable, Iterable, Mapping

import lcm
import numpy as np
import stridefix


class LogReadError(Exception):
    """A log file could not be opened or is not an LCM event log. The message names the file."""

    def __init__(self, path: str, reason: str):
        super().__init__(f"{path}: {reason}")
        self.path = path
        self.reason = reason


class LogTruncatedWarning(UserWarning):
    """A log ends with a partial record (or contains unreadable bytes); the whole records were read."""


class Table:
    """Named, equal-length numpy columns: the analyzer's container for one channel.

    Parameters
    ----------
    columns : mapping of str to array_like
        Column name (with its unit, e.g. ``x_m``) → values, shape (n,). All columns must have the
        same length n.
    """

    def __init__(self, columns: Mapping[str, np.ndarray]):
        self._cols = {name: np.asarray(values) for name, values in columns.items()}
        lengths = {name: len(values) for name, values in self._cols.items()}
        if len(set(lengths.values())) > 1:
            raise ValueError(f"Table columns differ in length: {lengths}")

    @property
    def names(self) -> list[str]:
        """Column names, in insertion order."""
        return list(self._cols)

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self._cols[name]
        except KeyError:
            raise KeyError(f"no column {name!r}; columns are {self.names}") from None

    def __contains__(self, name: str) -> bool:
        return name in self._cols

    def __len__(self) -> int:
        return len(next(iter(self._cols.values()))) if self._cols else 0

    def __repr__(self) -> str:
        return f"Table(n={len(self)}, columns={self.names})"

    def rows(self, index) -> "Table":
        """Rows selected by a boolean mask or an integer index array, as a new Table."""
        return Table({name: values[index] for name, values in self._cols.items()})

    def sorted_by(self, name: str = "t_us") -> "Table":
        """A copy sorted by column ``name``, stable (equal keys keep their order)."""
        return self.rows(np.argsort(self[name], kind="stable"))

    def to_dict(self) -> dict[str, np.ndarray]:
        """The columns as a plain dict (shared arrays, not copies)."""
        return dict(self._cols)


@dataclasses.dataclass
class LogData:
    """Everything read from one set of logs.

    Attributes
    ----------
    inputs : list of dict
        Per file: ``path``, ``bytes`` (file size), ``events`` (whole records read),
        ``truncated_bytes`` (trailing bytes that are not a whole record), ``skipped_bytes``
        (bytes skipped between records while resynchronising).
    tables : dict of str to Table
        Channel → decoded columns (see the module docstring); only channels that had messages.
    messages : dict of str to int
        Channel → events seen, all channels (known, unknown, undecodable).
    unknown_channels : dict of str to int
        Events on channels the analyzer has no type for.
    decode_errors : dict of str to int
        Events on known channels whose payload failed to decode.
    health : dict
        Fields of the last ``HEALTH`` report (latest host time), ``{}`` if none.
    config : dict of str to str
        Effective configuration from ``CONFIG`` (key → value); later logs win on conflicts.
    versions : dict of str to str
        ``version`` and ``dbc_sha256`` from ``CONFIG``.
    warnings : list of str
        Human-readable notes (truncation, decode errors, config conflicts).
    """

    inputs: list = dataclasses.field(default_factory=list)
    tables: dict = dataclasses.field(default_factory=dict)
    messages: dict = dataclasses.field(default_factory=dict)
    unknown_channels: dict = dataclasses.field(default_factory=dict)
    decode_errors: dict = dataclasses.field(default_factory=dict)
    health: dict = dataclasses.field(default_factory=dict)
    config: dict = dataclasses.field(default_factory=dict)
    versions: dict = dataclasses.field(default_factory=dict)
    warnings: list = dataclasses.field(default_factory=list)

    def table(self, channel: str) -> Table | None:
        """The channel's Table, or None when the logs had no decodable message on it."""
        return self.tables.get(channel)


# --- per-type row flatteners: message -> tuple of column values --------------------------------


def _xyz(prefix: str, unit: str) -> list[str]:
    return [f"{prefix}_{axis}_{unit}" for axis in "xyz"]


_HEALTH_FIELDS = list(stridefix.health_t.__slots__)

# channel -> (type, column names, row function)
_CHANNELS: dict[str, tuple[type, list[str], Callable]] = {
    "IMU": (
        stridefix.imu_t,
        ["t_us", "seq", *_xyz("accel", "mps2"), *_xyz("gyro", "radps")],
        lambda m: (m.t_us, m.seq, *m.accel_mps2, *m.gyro_radps),
    ),
    "MAG": (stridefix.mag_t, ["t_us", "seq", *_xyz("field", "ut")], lambda m: (m.t_us, m.seq, *m.field_ut)),
    "BARO": (
        stridefix.baro_t,
        ["t_us", "seq", "pressure_pa", "temperature_degc"],
        lambda m: (m.t_us, m.seq, m.pressure_pa, m.temperature_degc),
    ),
    "WIFI": (
        stridefix.wifi_scan_t,
        ["t_us", "scan_id", "complete", "n_ap"],
        lambda m: (m.t_us, m.scan_id, bool(m.complete), m.n_ap),
    ),
    "GNSS": (
        stridefix.gnss_t,
        ["t_us", "lat_deg", "lon_deg", "alt_m", "accuracy_m"],
        lambda m: (m.t_us, m.lat_deg, m.lon_deg, m.alt_m, m.accuracy_m),
    ),
    "STEP": (
        stridefix.step_t,
        ["t_us", "index", "length_m", "accel_range_mps2", "period_s", "heading_rad", "activity", "floor"],
        lambda m: (
            m.t_us,
            m.index,
            m.length_m,
            m.accel_range_mps2,
            m.period_s,
            m.heading_rad,
            m.activity,
            m.floor,
        ),
    ),
    "FIX": (
        stridefix.fix_t,
        [
            "t_us",
            "method",
            "x_m",
            "y_m",
            "floor",
            "accuracy_m",
            "n_ap_used",
            "innovation_x_m",
            "innovation_y_m",
            "innovation_var_m2",
            "test_ratio",
            "alpha",
            "accuracy_factor",
            "drift",
            "accepted",
            "reason",
            "reason_text",
        ],
        lambda m: (
            m.t_us,
            m.method,
            m.x_m,
            m.y_m,
            m.floor,
            m.accuracy_m,
            m.n_ap_used,
            m.innovation_m[0],
            m.innovation_m[1],
            m.innovation_var_m2,
            m.test_ratio,
            m.alpha,
            m.accuracy_factor,
            m.drift,
            bool(m.accepted),
            m.reason,
            m.reason_text,
        ),
    ),
    "POSE": (
        stridefix.pose_t,
        ["t_us", "x_m", "y_m", "floor", "heading_rad", "sigma_m", "step_count", "scheme"],
        lambda m: (m.t_us, m.x_m, m.y_m, m.floor, m.heading_rad, m.sigma_m, m.step_count, m.scheme),
    ),
    "TRUTH": (
        stridefix.truth_t,
        ["t_us", "x_m", "y_m", "floor", "heading_rad", "step_count", "source"],
        lambda m: (m.t_us, m.x_m, m.y_m, m.floor, m.heading_rad, m.step_count, m.source),
    ),
    "HEALTH": (stridefix.health_t, _HEALTH_FIELDS, lambda m: tuple(getattr(m, f) for f in _HEALTH_FIELDS)),
    "CONFIG": (stridefix.config_t, [], None),  # not a table: see _Collector.add_config
}

#: The channels :func:`read_logs` knows how to decode.
KNOWN_CHANNELS = tuple(_CHANNELS)

# numpy dtype per column (anything not listed is float64)
_INT_COLUMNS = {
    "t_us",
    "seq",
    "scan_id",
    "n_ap",
    "index",
    "activity",
    "method",
    "floor",
    "n_ap_used",
    "reason",
    "step_count",
    "scheme",
    "source",
} | {f for f in _HEALTH_FIELDS if not f.startswith("loop_")}
_BOOL_COLUMNS = {"complete", "accepted"}
_STR_COLUMNS = {"reason_text"}


def _column(name: str, values: list) -> np.ndarray:
    if name in _BOOL_COLUMNS:
        return np.asarray(values, dtype=bool)
    if name in _STR_COLUMNS:
        return np.asarray(values, dtype=str)
    if name in _INT_COLUMNS:
        return np.asarray(values, dtype=np.int64)
    return np.asarray(values, dtype=np.float64)


class _Collector:
    """Accumulates decoded rows from any number of files, then builds the tables."""

    def __init__(self, decode: set[str]):
        self.decode = decode
        self.rows: dict[str, list[tuple]] = {ch: [] for ch in _CHANNELS}
        self.wifi_aps: list[tuple] = []  # (scan row, bssid, rssi_dbm, freq_mhz)
        self.data = LogData()

    def add_event(self, channel: str, payload: bytes, path: str) -> None:
        d = self.data
        d.messages[channel] = d.messages.get(channel, 0) + 1
        if channel not in _CHANNELS:
            d.unknown_channels[channel] = d.unknown_channels.get(channel, 0) + 1
            return
        if channel not in self.decode:
            return
        msg_type, _, row = _CHANNELS[channel]
        try:
            msg = msg_type.decode(payload)
            if channel == "CONFIG":
                self.add_config(msg, path)
                return
            values = row(msg)
        except Exception:  # noqa: BLE001 - any decode failure is bad data, counted not fatal
            d.decode_errors[channel] = d.decode_errors.get(channel, 0) + 1
            return
        if channel == "WIFI":
            scan_row = len(self.rows["WIFI"])
            self.wifi_aps.extend(
                (scan_row, b, r, f) for b, r, f in zip(msg.bssid, msg.rssi_dbm, msg.freq_mhz)
            )
        self.rows[channel].append(values)

    def add_config(self, msg, path: str) -> None:
        d = self.data
        for key, value in zip(msg.key, msg.value):
            if key in d.config and d.config[key] != value:
                d.warnings.append(
                    f"{path}: CONFIG key {key!r} = {value!r} replaces "
                    f"{d.config[key]!r} from an earlier CONFIG message"
                )
            d.config[key] = value
        d.versions.update(version=msg.version, dbc_sha256=msg.dbc_sha256)

    def finish(self) -> LogData:
        d = self.data
        for channel, (_, names, _) in _CHANNELS.items():
            rows = self.rows[channel]
            if not names or not rows:
                continue
            cols = list(zip(*rows))
            table = Table({name: _column(name, list(col)) for name, col in zip(names, cols)})
            if channel == "WIFI":
                # sort scans by time and renumber the AP rows' scan_row to match
                order = np.argsort(table["t_us"], kind="stable")
                table = table.rows(order)
                new_row = np.empty(len(order), dtype=np.int64)
                new_row[order] = np.arange(len(order))
                aps = list(zip(*self.wifi_aps)) if self.wifi_aps else [[], [], [], []]
                d.tables["WIFI_AP"] = Table(
                    {
                        "scan_row": new_row[np.asarray(aps[0], dtype=np.int64)],
                        "bssid": np.asarray(aps[1], dtype=np.int64),
                        "rssi_dbm": np.asarray(aps[2], dtype=np.float64),
                        "freq_mhz": np.asarray(aps[3], dtype=np.int64),
                    }
                )
            elif channel == "HEALTH":
                # counters never decrease: the latest report by host clock is the final state
                table = table.rows(np.argsort(table["host_t_us"], kind="stable"))
                d.health = {name: table[name][-1].item() for name in table.names}
                table = table.sorted_by("t_us")
            else:
                table = table.sorted_by("t_us")
            d.tables[channel] = table
        for channel, n in sorted(d.decode_errors.items()):
            d.warnings.append(
                f"{n} message(s) on channel {channel} failed to decode (wrong type or corrupt payload)"
            )
        return d


_SYNC_WORD = bytes.fromhex("EDA1DA01")  # first 4 bytes of every LCM log record (big-endian)
_RECORD_OVERHEAD = 4 + 8 + 8 + 4 + 4  # sync word, event number, timestamp, channel and data lengths
_MAX_CHANNEL_BYTES = 255  # sanity bound when salvaging (LCM itself allows 63)
_CHUNK = 1 << 20


def _find_sync(f, offset: int) -> int | None:
    """Byte offset of the first LCM sync word at or after ``offset``, or None."""
    f.seek(offset)
    carry = b""
    base = offset
    while True:
        chunk = f.read(_CHUNK)
        if not chunk:
            return None
        buf = carry + chunk
        hit = buf.find(_SYNC_WORD)
        if hit >= 0:
            return base + hit
        carry = buf[-3:]
        base += len(buf) - len(carry)


def _parse_record(f, offset: int, size: int) -> tuple[str, bytes, int] | None:
    """The whole record starting at ``offset`` as (channel, payload, end offset), or None."""
    f.seek(offset)
    head = f.read(_RECORD_OVERHEAD)
    if len(head) < _RECORD_OVERHEAD or head[:4] != _SYNC_WORD:
        return None
    channel_len = int.from_bytes(head[20:24], "big", signed=True)
    data_len = int.from_bytes(head[24:28], "big", signed=True)
    end = offset + _RECORD_OVERHEAD + channel_len + data_len
    if not 0 < channel_len <= _MAX_CHANNEL_BYTES or data_len < 0 or end > size:
        return None
    try:
        channel = f.read(channel_len).decode("utf-8")
    except UnicodeDecodeError:
        return None
    if not channel.isprintable():
        return None
    return channel, f.read(data_len), end


def _read_file(path: str, collector: _Collector) -> None:
    """Read every whole record of one log into ``collector``; note truncation and skipped bytes.

    ``lcm.EventLog`` does the reading. Its reader (LCM 1.5) stops for good at the first bytes that
    are not a record, and also drops the whole record just before them (it checks the header that
    follows each record). So when it stops before the end of the file, the records from there on
    are salvaged by hand (sync word search + header check) and ``lcm.EventLog`` resumes after them.
    """
    if not os.path.exists(path):
        raise LogReadError(path, "no such file")
    if not os.path.isfile(path):
        raise LogReadError(path, "not a regular file")
    if not os.access(path, os.R_OK):
        raise LogReadError(path, "permission denied")
    try:
        log = lcm.EventLog(path, "r")
        raw = open(path, "rb")
    except (OSError, ValueError) as exc:
        raise LogReadError(path, f"cannot open as an LCM event log ({exc})") from exc
    size = os.path.getsize(path)
    events = skipped = salvaged = 0
    end_of_last = 0  # byte offset just past the last whole record read
    try:
        while True:
            event = log.read_next_event()
            if event is not None:
                channel = event.channel
                if isinstance(channel, bytes):
                    channel = channel.decode("utf-8", "replace")
                end = log.tell()
                expected = _RECORD_OVERHEAD + len(channel.encode()) + len(event.data)
                skipped += max(0, end - end_of_last - expected)
                end_of_last = end
                events += 1
                collector.add_event(channel, event.data, path)
                continue
            if end_of_last >= size:
                break
            # the reader stopped early: find the next whole record by hand
            scan, record = end_of_last, None
            while record is None:
                at = _find_sync(raw, scan)
                if at is None:
                    break
                record = _parse_record(raw, at, size)
                scan = at + 1
            if record is None:
                break  # only a partial record or junk up to the end: truncated
            channel, payload, end = record
            skipped += at - end_of_last
            end_of_last = end
            events += 1
            salvaged += 1
            collector.add_event(channel, payload, path)
            log.seek(end_of_last)
    finally:
        log.close()
        raw.close()
    trailing = size - end_of_last
    info = {
        "path": path,
        "bytes": size,
        "events": events,
        "truncated_bytes": trailing,
        "skipped_bytes": skipped,
        "salvaged_events": salvaged,
    }
    collector.data.inputs.append(info)
    if events == 0 and size > 0:
        with open(path, "rb") as f:
            head = f.read(4)
        if head != _SYNC_WORD:
            raise LogReadError(path, f"not an LCM event log (no LCM sync word; {size} bytes)")
    notes = []
    if trailing:
        notes.append(
            f"ends with {trailing} byte(s) that are not a whole record (truncated?); "
            f"read the {events} whole record(s) before them"
        )
    if skipped:
        notes.append(f"{skipped} byte(s) between records were unreadable and skipped")
    for note in notes:
        text = f"{path}: {note}"
        collector.data.warnings.append(text)
        warnings.warn(text, LogTruncatedWarning, stacklevel=3)


def read_logs(paths: Iterable[str | os.PathLike], decode: Iterable[str] | None = None) -> LogData:
    """Read and merge LCM event logs.

    Parameters
    ----------
    paths : iterable of str or path
        One or more LCM event logs. Events of all files are merged; each channel's table is then
        sorted by the messages' own ``t_us`` [µs].
    decode : iterable of str, optional
        Channels to decode (default: all of :data:`KNOWN_CHANNELS`). Other channels are only
        counted in ``messages``, which is much faster for long IMU-heavy logs.

    Returns
    -------
    LogData
        The merged tables, counts, last health report, configuration and warnings.

    Raises
    ------
    LogReadError
        A file is missing, not readable, or holds no LCM record at all; the message names it.
    """
    paths = [os.fspath(p) for p in paths]
    if not paths:
        raise ValueError("read_logs: no log paths given")
    wanted = set(KNOWN_CHANNELS if decode is None else decode)
    unknown = wanted - set(KNOWN_CHANNELS)
    if unknown:
        raise ValueError(
            f"read_logs: cannot decode channel(s) {sorted(unknown)}; "
            f"known channels are {list(KNOWN_CHANNELS)}"
        )
    collector = _Collector(wanted)
    for path in paths:
        _read_file(path, collector)
    return collector.finish()


def read_table(path: str | os.PathLike, channel: str) -> Table | None:
    """One channel of one log (``None`` when it has none), a truncated tail read silently: the
    stridefixd logs the benchmarks read back may end mid-record when a run is cut short."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        return read_logs([path], decode=(channel,)).table(channel)
