"""An LCM event log's records located with numpy, for reading only the channels wanted.

:func:`index_file` reads a whole log into memory and finds every record's channel and payload
without a Python step per record: it looks for the LCM sync word (0xEDA1DA01) at every byte, reads
the record headers found there (int64 event number, int64 timestamp, int32 channel length, int32
data length, all big-endian, then the channel name and the payload) and checks that they chain: the
first record starts at byte 0, each ends where the next begins, the last ends at the end of the
file. The 1-hour walk's log (650 k records, 62 MB) is indexed in 0.14 s of CPU, where
``lcm.EventLog`` took 1.1 s just to hand over the records one by one; the caller then decodes only
the channels it needs (:mod:`.lcmdecode` vectorises the fixed-layout ones).

Anything else (a record cut short, junk between records, a sync word inside a payload that breaks
the chain, a channel name that ``lcm.EventLog`` would read differently) gives ``None``: the caller
then reads the file record by record with :func:`stridefix_analyzer.io.lcmfile.read_file`, which
salvages and reports. So both readers always see the same records.
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any

import numpy as np
import numpy.typing as npt

_SYNC = (0xED, 0xA1, 0xDA, 0x01)
_HEADER_BYTES = 4 + 8 + 8 + 4 + 4  # sync word, event number, timestamp, channel and data lengths
#: liblcm's reader refuses a record whose channel length is not in 1..999 (eventlog.c)
_MAX_CHANNEL_BYTES = 999
#: more distinct channels than this and the per-channel passes of _channel_names would cost more than
#: reading the log record by record
_MAX_CHANNELS = 64
#: zero bytes after the file's in memory, so that the last header can be read as one fixed-size row
PAD_BYTES = 8

Array = npt.NDArray[Any]


@dataclasses.dataclass(frozen=True)
class LogIndex:
    """Where each record of one log is.

    Attributes
    ----------
    data : ndarray of uint8, shape (n_bytes,)
        The whole file.
    channels : list of str
        The distinct channel names, in the order of their first record.
    channel_of : ndarray of int64, shape (n_records,)
        Each record's channel, as an index into ``channels``.
    payload_at : ndarray of int64, shape (n_records,)
        Byte offset of each record's payload in ``data``.
    payload_len : ndarray of int64, shape (n_records,)
        Each payload's length [bytes].
    """

    data: Array
    channels: list[str]
    channel_of: Array
    payload_at: Array
    payload_len: Array

    def __len__(self) -> int:
        return len(self.channel_of)

    def counts(self) -> dict[str, int]:
        """Channel → records, in the order of each channel's first record."""
        n = np.bincount(self.channel_of, minlength=len(self.channels))
        return {name: int(k) for name, k in zip(self.channels, n)}

    def records_of(self, channel: str) -> Array:
        """The record numbers (log order) of ``channel``; empty when it has none."""
        if channel not in self.channels:
            return np.zeros(0, dtype=np.int64)
        return np.flatnonzero(self.channel_of == self.channels.index(channel))

    def payload(self, record: int) -> bytes:
        """One record's payload."""
        at = int(self.payload_at[record])
        return self.data[at : at + int(self.payload_len[record])].tobytes()


def index_bytes(data: Array) -> LogIndex | None:
    """The :class:`LogIndex` of a whole log held in ``data`` (uint8, followed by at least
    :data:`PAD_BYTES` bytes that are not part of it), or ``None`` when its records do not chain from
    the first byte to the last (module docstring)."""
    size = len(data) - PAD_BYTES
    if size < _HEADER_BYTES:
        return None
    start = np.flatnonzero(data[: size - 3] == _SYNC[0])
    for k in (1, 2, 3):
        start = start[data[start + k] == _SYNC[k]]
    start = start[start <= size - _HEADER_BYTES]
    if not len(start) or start[0] != 0:
        return None
    # each record's header and the first 8 bytes of its channel name, one row per record (gathering
    # rows of a sliding window view indexes by record, not by byte)
    head = np.lib.stride_tricks.sliding_window_view(data, _HEADER_BYTES + 8)[start]
    lengths = np.ascontiguousarray(head[:, 20:28]).view(">i4")
    channel_len = lengths[:, 0].astype(np.int64)
    data_len = lengths[:, 1].astype(np.int64)
    if channel_len.min() < 1 or channel_len.max() > _MAX_CHANNEL_BYTES or data_len.min() < 0:
        return None
    end = start + _HEADER_BYTES + channel_len + data_len
    # one chain: a sync word inside a payload starts no record of its own, so any such word breaks it
    if end[-1] != size or np.any(end[:-1] != start[1:]):
        return None
    names = _channel_names(data, head[:, _HEADER_BYTES:], start + _HEADER_BYTES, channel_len)
    if names is None:
        return None
    channels, channel_of = names
    return LogIndex(data[:size], channels, channel_of, start + _HEADER_BYTES + channel_len, data_len)


def _channel_names(data: Array, prefix: Array, at: Array, length: Array) -> tuple[list[str], Array] | None:
    """The distinct channel names (first-record order) and each record's index into them, from the
    names' first 8 bytes ``prefix`` (n, 8) and their offsets ``at`` and lengths in ``data``.

    ``None`` when a name is not UTF-8 or holds a NUL byte (liblcm hands such names over cut or
    altered), when two names share their length and first 8 bytes (too rare to be worth telling
    apart here), or when there are more than :data:`_MAX_CHANNELS`."""
    key = np.ascontiguousarray(np.where(np.arange(8) < length[:, None], prefix, 0)).view(">u8").ravel()
    channel_of = np.full(len(at), -1, dtype=np.int64)
    names: list[str] = []
    first = 0
    # one channel at a time, the first record not yet named naming the next: a log has a handful of
    # channels, so this is a few passes over the records, and it yields them in first-record order
    while first >= 0:
        same = (key == key[first]) & (length == length[first])
        n = int(length[first])
        name = data[at[first] : at[first] + n].tobytes()
        if n > 8:
            rest = data[at[same][:, None] + np.arange(8, n)]
            if np.any(rest != np.frombuffer(name[8:], np.uint8)):
                return None
        if b"\0" in name or len(names) == _MAX_CHANNELS:
            return None
        try:
            names.append(name.decode("utf-8"))
        except UnicodeDecodeError:
            return None
        channel_of[same] = len(names) - 1
        unnamed = np.flatnonzero(channel_of < 0)
        first = int(unnamed[0]) if len(unnamed) else -1
    return names, channel_of


def index_file(path: str) -> LogIndex | None:
    """:func:`index_bytes` of the file at ``path`` (read whole; the caller has checked it is a
    readable regular file)."""
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        data = np.empty(size + PAD_BYTES, dtype=np.uint8)
        if f.readinto(data.data[:size]) != size:
            return None  # the file changed under us: let the record-by-record reader cope
    data[size:] = 0
    return index_bytes(data)
