"""LCM event log files, record by record, with salvage past damaged bytes.

:func:`read_file` hands every whole record of one log (channel, payload) to a callback and counts
what it could not read: trailing bytes of a record cut short, and bytes skipped between records.
Decoding the payloads is :mod:`.logread`'s job.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from typing import Any, BinaryIO

import lcm
from stridefix_common.exits import NothingValid


class LogReadError(Exception):
    """A log file could not be opened or is not an LCM event log. The message names the file."""

    def __init__(self, path: str, reason: str) -> None:
        super().__init__(f"{path}: {reason}")
        self.path = path
        self.reason = reason

    def __reduce__(self) -> tuple[type[LogReadError], tuple[str, str]]:
        # a realbench worker's error must reach the parent process whole (pickling rebuilds an exception
        # from self.args, which is the one formatted message here)
        return (type(self), (self.path, self.reason))


class NotALogError(LogReadError, NothingValid):
    """The file was read but holds no LCM record (no sync word): nothing valid in it."""


class LogTruncatedWarning(UserWarning):
    """A log ends with a partial record (or contains unreadable bytes); the whole records were read."""


_SYNC_WORD = bytes.fromhex("EDA1DA01")  # first 4 bytes of every LCM log record (big-endian)
_RECORD_OVERHEAD = 4 + 8 + 8 + 4 + 4  # sync word, event number, timestamp, channel and data lengths
_MAX_CHANNEL_BYTES = 255  # sanity bound when salvaging (LCM itself allows 63)
_CHUNK = 1 << 20


def _find_sync(f: BinaryIO, offset: int) -> int | None:
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


def _parse_record(f: BinaryIO, offset: int, size: int) -> tuple[str, bytes, int] | None:
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


def check_readable(path: str) -> None:
    """Raise :class:`LogReadError` naming ``path`` unless it is a readable regular file."""
    if not os.path.exists(path):
        raise LogReadError(path, "no such file")
    if not os.path.isfile(path):
        raise LogReadError(path, "not a regular file")
    if not os.access(path, os.R_OK):
        raise LogReadError(path, "permission denied")


def file_counts(
    path: str, size: int, events: int, trailing: int = 0, skipped: int = 0, salvaged: int = 0
) -> dict[str, Any]:
    """One file's entry of ``LogData.inputs`` (see :func:`read_file`)."""
    return {
        "path": path,
        "bytes": size,
        "events": events,
        "truncated_bytes": trailing,
        "skipped_bytes": skipped,
        "salvaged_events": salvaged,
    }


def require_records(inputs: Iterable[Mapping[str, Any]]) -> None:
    """Raise :class:`NotALogError` for the first file of a read (``LogData.inputs``, :func:`file_counts`)
    without one whole record: empty, or cut short inside its first record. A command's input so is
    read, but nothing valid; the readers themselves take it as an empty log (a replay that wrote
    nothing, e.g. with ``--channels`` none of its messages went to)."""
    for info in inputs:
        if info["events"] == 0:
            raise NotALogError(
                info["path"], f"nothing valid in the input: no whole LCM record ({info['bytes']} bytes)"
            )


def read_file(path: str, on_event: Callable[[str, bytes], None]) -> tuple[dict[str, Any], list[str]]:
    """Pass every whole record of one log to ``on_event(channel, payload)``.

    Returns the file's counts (``path``, ``bytes``, ``events``, ``truncated_bytes``,
    ``skipped_bytes``, ``salvaged_events``) and notes on truncation and skipped bytes.

    ``lcm.EventLog`` does the reading. Its reader (LCM 1.5) stops for good at the first bytes that
    are not a record, and also drops the whole record just before them (it checks the header that
    follows each record). So when it stops before the end of the file, the records from there on
    are salvaged by hand (sync word search + header check) and ``lcm.EventLog`` resumes after them.
    """
    check_readable(path)
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
                on_event(channel, event.data)
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
            on_event(channel, payload)
            log.seek(end_of_last)
    finally:
        log.close()
        raw.close()
    trailing = size - end_of_last
    info = file_counts(path, size, events, trailing, skipped, salvaged)
    if events == 0 and size > 0:
        with open(path, "rb") as f:
            head = f.read(4)
        if head != _SYNC_WORD:
            raise NotALogError(
                path, f"nothing valid in the input: not an LCM event log (no LCM sync word; {size} bytes)"
            )
    notes: list[str] = []
    if trailing:
        notes.append(
            f"ends with {trailing} byte(s) that are not a whole record (truncated?); "
            f"read the {events} whole record(s) before them"
        )
    if skipped:
        notes.append(f"{skipped} byte(s) between records were unreadable and skipped")
    return info, [f"{path}: {note}" for note in notes]
