"""The pose tracks of StrideFix logs, and any channel's messages kept apart by channel.

:func:`read_channels` reads the named channels of one or more logs into one :class:`Table` per
*channel* (``POSE`` and ``POSE_EKF`` stay apart, unlike :func:`~stridefix_analyzer.io.logread.read_logs`,
which folds every pose channel into one POSE table): an export must carry each channel's messages as
the log has them, the primary pose's copies on ``POSE`` included. Files are read record by record
(:func:`~stridefix_analyzer.io.lcmfile.read_file`, which salvages damaged files); messages that fail
to decode are counted, not fatal.

:func:`read_tracks` picks the tracks to export:

* the default, ``primary``: the messages of the ``POSE`` channel, the pose the product shows (the
  controller's, or the scheme the firmware follows without one). A log that carries every scheme on
  POSE (written before the per-scheme channels) has no such channel of its own: its primary is the
  controller's rows there;
* a scheme name: that scheme's rows of the analyzer's POSE table (``read_logs``);
* ``all``: every scheme of that table, in the registry's order.

Each :class:`Track` is sorted by ``t_us`` (the message's own board time [µs]).
"""

from __future__ import annotations

import dataclasses
import datetime
import os
import warnings
from collections.abc import Iterable, Sequence

import numpy as np
import numpy.typing as npt
from stridefix import pose_t
from stridefix_common.exits import NothingValid

from stridefix_analyzer import schemes as registry
from stridefix_analyzer.io.channels import CHANNELS, POSE, POSE_SCHEME_CHANNELS, table_of
from stridefix_analyzer.io.lcmfile import LogTruncatedWarning, read_file
from stridefix_analyzer.io.logread import Table, read_logs

#: the name of the default track
PRIMARY = "primary"
#: ``--scheme all``
ALL = "all"


class TrackError(ValueError):
    """The logs hold no track to export as asked; the message names the scheme or channel."""


class NoPoseError(TrackError, NothingValid):
    """The logs were read but hold not one pose to export."""


@dataclasses.dataclass(frozen=True)
class Channels:
    """Messages of the channels read, one table per channel (columns of its LCM type).

    Attributes
    ----------
    tables : dict of str to Table
        Channel → its messages sorted by ``t_us``, only channels that had a decodable message.
    counts : dict of str to int
        Channel → messages seen on it (decodable or not), every channel of the logs.
    decode_errors : dict of str to int
        Channel → messages of the channels read that failed to decode.
    """

    tables: dict[str, Table]
    counts: dict[str, int]
    decode_errors: dict[str, int]


def read_channels(paths: Iterable[str | os.PathLike[str]], channels: Iterable[str]) -> Channels:
    """The messages of ``channels`` in the logs ``paths``, each channel its own table.

    Raises
    ------
    LogReadError
        A file is missing, unreadable or not an LCM log (the message names it).
    """
    wanted = {c for c in channels if table_of(c) in CHANNELS}
    rows: dict[str, list[tuple[object, ...]]] = {c: [] for c in wanted}
    counts: dict[str, int] = {}
    errors: dict[str, int] = {}

    def on_event(channel: str, payload: bytes) -> None:
        counts[channel] = counts.get(channel, 0) + 1
        if channel not in wanted:
            return
        spec = CHANNELS[table_of(channel)]
        try:
            rows[channel].append(spec.row(spec.msg_type.decode(payload)))
        except Exception:  # noqa: BLE001 - a payload that does not decode is bad data, counted
            errors[channel] = errors.get(channel, 0) + 1

    for path in paths:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)  # whole records are what we export
            read_file(os.fspath(path), on_event)
    tables = {}
    for channel in sorted(wanted):
        if rows[channel]:
            spec = CHANNELS[table_of(channel)]
            cols = list(zip(*rows[channel]))
            table = Table({n: np.asarray(c, dtype=d) for (n, d), c in zip(spec.columns.items(), cols)})
            tables[channel] = table.sorted_by("t_us")
    return Channels(tables, counts, errors)


@dataclasses.dataclass(frozen=True)
class Track:
    """One pose track.

    Attributes
    ----------
    name : str
        ``primary`` or the scheme's name.
    channel : str
        The channel the poses came from (``POSE``, ``POSE_EKF``, ...).
    poses : Table
        The pose_t columns (``t_us``, ``x_m``, ``y_m``, ``floor``, ``heading_rad``, ``sigma_m``,
        ``scheme``, ...), sorted by ``t_us``.
    """

    name: str
    channel: str
    poses: Table

    def __len__(self) -> int:
        return len(self.poses)

    def legs(self) -> list[slice]:
        """The runs of poses on one floor, in time order: a floor change starts a new leg."""
        floor = np.asarray(self.poses["floor"])
        if floor.size == 0:
            return []
        cuts = [0, *(np.flatnonzero(np.diff(floor) != 0) + 1).tolist(), floor.size]
        return [slice(a, b) for a, b in zip(cuts[:-1], cuts[1:])]


def _scheme_channel(code: int) -> str:
    return POSE_SCHEME_CHANNELS.get(code, POSE)


def read_tracks(paths: Sequence[str | os.PathLike[str]], scheme: str | None = None) -> list[Track]:
    """The tracks to export (module docstring): ``scheme`` None for the primary pose, a scheme's name
    or id, or ``all``.

    Raises
    ------
    LogReadError
        A log cannot be read.
    TrackError
        No pose to export (no POSE message, or none of the scheme asked for).
    UnknownSchemeError
        ``scheme`` is not a scheme of pose_t.lcm.
    """
    if scheme is None or scheme == PRIMARY:
        return [_primary(paths)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        pose = read_logs(paths, decode=[POSE]).table(POSE)
    if pose is None or len(pose) == 0:
        raise NoPoseError(f"{_names(paths)}: no POSE message in the log")
    present = np.unique(pose["scheme"])
    if scheme == ALL:
        codes = [s.id for s in registry.SCHEMES if s.id in present]
        codes += sorted(int(c) for c in present if int(c) not in codes)
    else:
        code = registry.scheme_code(scheme)
        if code not in present:
            raise TrackError(
                f"{_names(paths)}: no pose of scheme {registry.scheme_name(code)}; the log has "
                f"{', '.join(registry.scheme_name(c) for c in present)}"
            )
        codes = [code]
    return [
        Track(registry.scheme_name(c), _scheme_channel(c), pose.rows(np.asarray(pose["scheme"]) == c))
        for c in codes
    ]


def _primary(paths: Sequence[str | os.PathLike[str]]) -> Track:
    read = read_channels(paths, [POSE, *POSE_SCHEME_CHANNELS.values()])
    pose = read.tables.get(POSE)
    if pose is None:
        if read.tables:
            raise TrackError(
                f"{_names(paths)}: no message on the POSE channel (the primary pose); name a scheme "
                "with --scheme NAME (or all)"
            )
        raise NoPoseError(f"{_names(paths)}: no POSE message in the log")
    if not any(ch in read.tables for ch in POSE_SCHEME_CHANNELS.values()):
        # every scheme on POSE: the primary pose is the controller's
        mine: npt.NDArray[np.bool_] = np.asarray(pose["scheme"]) == pose_t.SCHEME_CONTROLLER
        if not mine.any():
            raise TrackError(
                f"{_names(paths)}: every scheme is on the POSE channel and none is the controller's; "
                "name one with --scheme NAME (or all)"
            )
        pose = pose.rows(mine)
    return Track(PRIMARY, POSE, pose)


def _names(paths: Sequence[str | os.PathLike[str]]) -> str:
    return ", ".join(os.fspath(p) for p in paths)


#: board time 0 when the user names no start: the Unix epoch (board time has no date of its own)
EPOCH = datetime.datetime(1970, 1, 1, tzinfo=datetime.timezone.utc)


def utc_times(t_us: npt.ArrayLike, start: datetime.datetime = EPOCH) -> list[datetime.datetime]:
    """Board times [µs] as UTC datetimes: ``start`` is board time 0 (µs resolution)."""
    return [start + datetime.timedelta(microseconds=int(t)) for t in np.asarray(t_us, dtype=np.int64)]
