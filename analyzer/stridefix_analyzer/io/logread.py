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
FIX       t_us, method, scheme, x_m, y_m, floor, accuracy_m, n_ap_used, innovation_{x,y}_m,
          innovation_var_m2, test_ratio, accuracy_factor, drift, alpha, accepted, reason, reason_text
POSE      t_us, x_m, y_m, floor, heading_rad, sigma_m, step_count, scheme  (every pose channel)
TRUTH     t_us, x_m, y_m, floor, heading_rad, step_count, source
HEALTH    every health_t field (counters over time); the last report is also in ``LogData.health``
========  ==========================================================================================

The columns are the fields of each channel's LCM type (:mod:`.channels` derives them), so a field
added to a ``.lcm`` file appears here by itself; the list above is what the types hold today.

``CONFIG`` becomes the ``LogData.config`` key → value dict (plus ``LogData.versions``).

Poses: a log of today has each fusion scheme's poses on ``POSE_<SCHEME>`` and the primary pose on
``POSE`` (the controller's, scheme 8, or without an active controller a copy of one scheme's pose); a
log from before the split has every scheme's poses on ``POSE``. Both read into one ``POSE`` table,
the same rows either way: in a file with a ``POSE_<SCHEME>`` channel, the ``POSE`` messages of a
fusion scheme are copies of that scheme's own and are left out (``decode`` of any pose channel
decodes them all). ``LogData.messages`` counts each channel under its own name, and
``LogData.pose_channel_scheme`` keeps which scheme the POSE channel carried last, copies included:
the firmware's primary (:mod:`stridefix_analyzer.scoring.primary`).

Reading: an intact file (one unbroken chain of records) is indexed with numpy (:mod:`.lcmindex`),
only the channels asked for are decoded, and the fixed-layout ones all at once (:mod:`.lcmdecode`);
any other file is read record by record, with salvage, by :mod:`.lcmfile`. Both give the same
``LogData`` (``read_logs(..., indexed=False)`` forces the second; the tests compare them).

Errors: a missing or unreadable file raises :class:`LogReadError` naming it. Bad data is not an
error: unknown channels and messages that fail to decode are counted (by channel), and a log cut
short reads up to its last whole record, with a warning in ``LogData.warnings``.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import warnings
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
import numpy.typing as npt
import stridefix

from stridefix_analyzer.io.channels import CHANNELS, CONFIG_TYPE, POSE, POSE_CHANNELS, table_of
from stridefix_analyzer.io.lcmdecode import decode_columns
from stridefix_analyzer.io.lcmfile import (
    LogReadError,
    LogTruncatedWarning,
    check_readable,
    file_counts,
    read_file,
)
from stridefix_analyzer.io.lcmindex import LogIndex, index_file

__all__ = [
    "KNOWN_CHANNELS",
    "LogData",
    "LogReadError",
    "LogTruncatedWarning",
    "Table",
    "read_logs",
    "read_table",
]

Array = npt.NDArray[Any]


class Table:
    """Named, equal-length numpy columns: the analyzer's container for one channel.

    Parameters
    ----------
    columns : mapping of str to array_like
        Column name (with its unit, e.g. ``x_m``) → values, shape (n,). All columns must have the
        same length n.
    """

    def __init__(self, columns: Mapping[str, npt.ArrayLike]) -> None:
        self._cols = {name: np.asarray(values) for name, values in columns.items()}
        lengths = {name: len(values) for name, values in self._cols.items()}
        if len(set(lengths.values())) > 1:
            raise ValueError(f"Table columns differ in length: {lengths}")

    @property
    def names(self) -> list[str]:
        """Column names, in insertion order."""
        return list(self._cols)

    def __getitem__(self, name: str) -> Array:
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

    def rows(self, index: Array | list[int] | slice) -> Table:
        """Rows selected by a boolean mask or an integer index array, as a new Table."""
        return Table({name: values[index] for name, values in self._cols.items()})

    def sorted_by(self, name: str = "t_us") -> Table:
        """A copy sorted by column ``name``, stable (equal keys keep their order)."""
        return self.rows(np.argsort(self[name], kind="stable"))

    def to_dict(self) -> dict[str, Array]:
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
    type_mismatches : dict of str to int
        Of those, the events whose payload carries another LCM type hash than this build's type, the
        same foreign hash on more than one event: the log was written by another version of
        ``lcmtypes/`` (e.g. a stale stridefixd binary), not corrupted.
    health : dict
        Fields of the last ``HEALTH`` report (latest host time), ``{}`` if none.
    config : dict of str to str
        Effective configuration from ``CONFIG`` (key → value); later logs win on conflicts.
    versions : dict of str to str
        ``version`` and ``dbc_sha256`` from ``CONFIG``.
    warnings : list of str
        Human-readable notes (truncation, decode errors, config conflicts).
    pose_channel_scheme : int or None
        The scheme (pose_t.SCHEME_*) of the last message on the ``POSE`` channel itself, by ``t_us``,
        in a file that also has ``POSE_<SCHEME>`` channels: the primary pose the firmware chose
        (module docstring); None without such a file (an older log carries every scheme on POSE).
    """

    inputs: list[dict[str, Any]] = dataclasses.field(default_factory=list)
    tables: dict[str, Table] = dataclasses.field(default_factory=dict)
    messages: dict[str, int] = dataclasses.field(default_factory=dict)
    unknown_channels: dict[str, int] = dataclasses.field(default_factory=dict)
    decode_errors: dict[str, int] = dataclasses.field(default_factory=dict)
    type_mismatches: dict[str, int] = dataclasses.field(default_factory=dict)
    health: dict[str, Any] = dataclasses.field(default_factory=dict)
    config: dict[str, str] = dataclasses.field(default_factory=dict)
    versions: dict[str, str] = dataclasses.field(default_factory=dict)
    warnings: list[str] = dataclasses.field(default_factory=list)
    pose_channel_scheme: int | None = None

    def table(self, channel: str) -> Table | None:
        """The channel's Table, or None when the logs had no decodable message on it."""
        return self.tables.get(channel)


#: The channels :func:`read_logs` knows how to decode.
KNOWN_CHANNELS = (*CHANNELS, "CONFIG")
_KNOWN = frozenset(KNOWN_CHANNELS)
#: the tables the channels are read into (every pose channel into POSE), in channel order
_TABLES = tuple(dict.fromkeys(table_of(ch) for ch in CHANNELS))
_SCHEME_CONTROLLER = stridefix.pose_t.SCHEME_CONTROLLER


@dataclasses.dataclass
class _PoseFile:
    """One file's POSE rows that came on the POSE channel itself (absolute rows of the POSE table, in
    log order) and whether the file has per-scheme pose channels (then those of a fusion scheme are
    copies: module docstring)."""

    primary_rows: list[int] = dataclasses.field(default_factory=list)
    per_scheme: bool = False


class _Collector:
    """Accumulates decoded rows from any number of files, then builds the tables."""

    def __init__(self, decode: set[str]) -> None:
        self.decode = decode
        # channel -> its rows so far, in log order: lists of row tuples (decoded message by message)
        # and dicts of columns (decoded at once from an indexed file, :mod:`.lcmdecode`)
        self.chunks: dict[str, list[list[Any] | dict[str, Array]]] = {t: [] for t in _TABLES}
        self.n_rows = dict.fromkeys(_TABLES, 0)
        self.pose_files: list[_PoseFile] = []
        self.wifi_aps: list[tuple[int, int, float, int]] = []  # (scan row, bssid, rssi_dbm, freq_mhz)
        self.data = LogData()
        # channel -> leading 8 payload bytes that are not this build's type hash -> count
        self.foreign_hashes: dict[str, dict[bytes, int]] = {}

    def begin_file(self) -> None:
        self.pose_files.append(_PoseFile())

    def add_event(self, path: str, channel: str, payload: bytes) -> None:
        d = self.data
        d.messages[channel] = d.messages.get(channel, 0) + 1
        if channel not in _KNOWN:
            d.unknown_channels[channel] = d.unknown_channels.get(channel, 0) + 1
            return
        if channel in POSE_CHANNELS and channel != POSE:
            self.pose_files[-1].per_scheme = True
        if channel in self.decode:
            self.decode_event(path, channel, payload)

    def add_index(self, path: str, index: LogIndex) -> None:
        """All records of one indexed file: the same counts, rows and errors as :meth:`add_event`
        on each record in turn, with the fixed-layout channels decoded at once."""
        d = self.data
        for channel, n in index.counts().items():  # first-record order, as add_event meets them
            d.messages[channel] = d.messages.get(channel, 0) + n
            if channel not in _KNOWN:
                d.unknown_channels[channel] = d.unknown_channels.get(channel, 0) + n
        self.pose_files[-1].per_scheme = any(ch in POSE_CHANNELS and ch != POSE for ch in index.channels)
        one_by_one: list[tuple[str, Array]] = []
        for table, channels in _tables_of(index.channels, self.decode).items():
            # the pose channels together, in log order (the record-by-record reader's order)
            records = np.sort(np.concatenate([index.records_of(ch) for ch in channels]))
            columns = None
            if table != "CONFIG":
                spec = CHANNELS[table]
                at, size = index.payload_at[records], index.payload_len[records]
                columns = decode_columns(spec.msg_type, spec.columns, index.data, at, size)
            if columns is None:
                one_by_one.extend((ch, index.records_of(ch)) for ch in channels)
                continue
            if table == POSE and POSE in channels:
                primary = np.flatnonzero(index.channel_of[records] == index.channels.index(POSE))
                self.pose_files[-1].primary_rows.extend((self.n_rows[POSE] + primary).tolist())
            self.chunks[table].append(columns)
            self.n_rows[table] += len(records)
        # the rest in log order across channels: decode errors and CONFIG warnings keep their order
        if one_by_one:
            names = np.concatenate([np.full(len(r), i) for i, (_, r) in enumerate(one_by_one)])
            records = np.concatenate([r for _, r in one_by_one])
            for k in np.argsort(records, kind="stable"):
                self.decode_event(path, one_by_one[names[k]][0], index.payload(int(records[k])))

    def decode_event(self, path: str, channel: str, payload: bytes) -> None:
        d = self.data
        try:
            if channel == "CONFIG":
                self.add_config(CONFIG_TYPE.decode(payload), path)
                return
            spec = CHANNELS[table_of(channel)]
            msg = spec.msg_type.decode(payload)
            values = spec.row(msg)
        except Exception:  # noqa: BLE001 - any decode failure is bad data, counted not fatal
            d.decode_errors[channel] = d.decode_errors.get(channel, 0) + 1
            msg_type = CONFIG_TYPE if channel == "CONFIG" else CHANNELS[channel].msg_type
            if payload[:8] != msg_type._get_packed_fingerprint():
                foreign = self.foreign_hashes.setdefault(channel, {})
                foreign[payload[:8]] = foreign.get(payload[:8], 0) + 1
            return
        if channel == "WIFI":
            scan_row = self.n_rows["WIFI"]
            self.wifi_aps.extend(
                (scan_row, b, r, f) for b, r, f in zip(msg.bssid, msg.rssi_dbm, msg.freq_mhz)
            )
        table = table_of(channel)
        if channel == POSE:
            self.pose_files[-1].primary_rows.append(self.n_rows[POSE])
        chunks = self.chunks[table]
        if not chunks or not isinstance(chunks[-1], list):
            chunks.append([])
        chunks[-1].append(values)  # type: ignore[union-attr]
        self.n_rows[table] += 1

    def columns(self, channel: str) -> dict[str, Array] | None:
        """The channel's rows so far as columns (None without any)."""
        if not self.n_rows[channel]:
            return None
        spec = CHANNELS[channel]
        parts: list[dict[str, Array]] = []
        for chunk in self.chunks[channel]:
            if isinstance(chunk, dict):
                parts.append(chunk)
                continue
            cols = list(zip(*chunk))
            parts.append(
                {name: np.asarray(col, dtype=dtype) for (name, dtype), col in zip(spec.columns.items(), cols)}
            )
        if len(parts) == 1:
            return parts[0]
        return {name: np.concatenate([p[name] for p in parts]) for name in spec.columns}

    def add_config(self, msg: Any, path: str) -> None:
        d = self.data
        for key, value in zip(msg.key, msg.value):
            if key in d.config and d.config[key] != value:
                d.warnings.append(
                    f"{path}: CONFIG key {key!r} = {value!r} replaces "
                    f"{d.config[key]!r} from an earlier CONFIG message"
                )
            d.config[key] = value
        d.versions.update(version=msg.version, dbc_sha256=msg.dbc_sha256)

    def copies(self, pose: Table) -> Array:
        """The rows of the POSE table that are copies of a fusion scheme's own poses (module
        docstring), as a mask."""
        copy = np.zeros(len(pose), dtype=bool)
        for f in self.pose_files:
            if f.per_scheme and f.primary_rows:
                rows = np.asarray(f.primary_rows, dtype=np.int64)
                copy[rows] = pose["scheme"][rows] != _SCHEME_CONTROLLER
        return copy

    def pose_channel_scheme(self, pose: Table) -> int | None:
        """The scheme of the latest message on the POSE channel of a file with per-scheme channels."""
        rows = [r for f in self.pose_files if f.per_scheme for r in f.primary_rows]
        if not rows:
            return None
        at = np.asarray(rows, dtype=np.int64)
        last = at[np.argsort(pose["t_us"][at], kind="stable")[-1]]  # equal times: the later row
        return int(pose["scheme"][last])

    def finish(self) -> LogData:
        d = self.data
        for channel in _TABLES:
            columns = self.columns(channel)
            if columns is None:
                continue
            table = Table(columns)
            if channel == POSE:
                d.pose_channel_scheme = self.pose_channel_scheme(table)
                table = table.rows(~self.copies(table))
            if channel == "WIFI":
                # sort scans by time and renumber the AP rows' scan_row to match
                order = np.argsort(table["t_us"], kind="stable")
                table = table.rows(order)
                new_row = np.empty(len(order), dtype=np.int64)
                new_row[order] = np.arange(len(order))
                aps = list(zip(*self.wifi_aps)) if self.wifi_aps else [(), (), (), ()]
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
        for channel, foreign in sorted(self.foreign_hashes.items()):
            # one hash seen again and again is another type version; a lone one is a corrupt payload
            n = sum(k for k in foreign.values() if k > 1)
            if n:
                d.type_mismatches[channel] = n
                d.warnings.append(_mismatch_text(channel, n))
        return d


def read_logs(
    paths: Iterable[str | os.PathLike[str]], decode: Iterable[str] | None = None, indexed: bool = True
) -> LogData:
    """Read and merge LCM event logs.

    Parameters
    ----------
    paths : iterable of str or path
        One or more LCM event logs. Events of all files are merged; each channel's table is then
        sorted by the messages' own ``t_us`` [µs].
    decode : iterable of str, optional
        Channels to decode (default: all of :data:`KNOWN_CHANNELS`). Other channels are only
        counted in ``messages``, which is much faster for long IMU-heavy logs.
    indexed : bool, default True
        Locate the records of an intact file with :mod:`.lcmindex` and decode the fixed-layout
        channels at once (:mod:`.lcmdecode`): ~10x faster, the same result. False reads every file
        record by record through ``lcm.EventLog`` (what a damaged file gets anyway), the reference
        the fast path is tested against.

    Returns
    -------
    LogData
        The merged tables, counts, last health report, configuration and warnings.

    Raises
    ------
    LogReadError
        A file is missing, not readable, or holds no LCM record at all; the message names it.
    """
    files = [os.fspath(p) for p in paths]
    if not files:
        raise ValueError("read_logs: no log paths given")
    wanted = set(KNOWN_CHANNELS if decode is None else decode)
    if wanted & POSE_CHANNELS:
        wanted |= POSE_CHANNELS  # one table: the copies are told by the file's other pose channels
    unknown = wanted - set(KNOWN_CHANNELS)
    if unknown:
        raise ValueError(
            f"read_logs: cannot decode channel(s) {sorted(unknown)}; "
            f"known channels are {list(KNOWN_CHANNELS)}"
        )
    collector = _Collector(wanted)
    for path in files:
        collector.begin_file()
        index = _index(path) if indexed else None
        if index is not None:
            # one unbroken chain of records: nothing to salvage, and lcm.EventLog would read the same
            collector.add_index(path, index)
            info, notes = file_counts(path, len(index.data), len(index)), list[str]()
        else:
            info, notes = read_file(path, functools.partial(collector.add_event, path))
        collector.data.inputs.append(info)
        for text in notes:
            collector.data.warnings.append(text)
            warnings.warn(text, LogTruncatedWarning, stacklevel=2)
    return collector.finish()


def _index(path: str) -> LogIndex | None:
    """The file's :class:`LogIndex`, or None to read it record by record (which also names the file
    in any error)."""
    check_readable(path)
    try:
        return index_file(path)
    except OSError:
        return None


def _tables_of(channels: Iterable[str], decode: set[str]) -> dict[str, list[str]]:
    """The known channels of a file to decode, grouped by the table they go into (first-record
    order)."""
    out: dict[str, list[str]] = {}
    for channel in channels:
        if channel in _KNOWN and channel in decode:
            out.setdefault(table_of(channel), []).append(channel)
    return out


def _mismatch_text(channel: str, n: int) -> str:
    return (
        f"{n} message(s) on channel {channel} carry another LCM type hash than this build's: the log "
        "was written by another version of lcmtypes/ (a stale stridefixd? run make build)"
    )


def read_table(path: str | os.PathLike[str], channel: str) -> Table | None:
    """One channel of one log (``None`` when it has none), a truncated tail read silently: the
    stridefixd logs the benchmarks read back may end mid-record when a run is cut short.

    Raises :class:`LogReadError` when the channel's messages carry another type hash than this build
    knows: a benchmark must not score a stale firmware's log as if it had no such messages."""
    return read_tables(path, (channel,))[channel]


def read_tables(path: str | os.PathLike[str], channels: Iterable[str]) -> dict[str, Table | None]:
    """:func:`read_table` of several channels of one log, the file read once."""
    channels = tuple(channels)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        data = read_logs([path], decode=channels)
    for channel, n in data.type_mismatches.items():
        if table_of(channel) in {table_of(c) for c in channels}:
            raise LogReadError(os.fspath(path), _mismatch_text(channel, n))
    return {channel: data.table(table_of(channel)) for channel in channels}
