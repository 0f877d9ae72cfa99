"""The channels of a StrideFix log and their table columns, derived from the generated LCM types.

Each channel's columns are the fields of its type (``__slots__`` of the generated Python binding), in
declaration order: a scalar field is one column; a fixed-length array ``<name>_<unit>[n]`` becomes
``<name>_x_<unit>``, ``<name>_y_<unit>`` … (``accel_mps2[3]`` → ``accel_x_mps2``); a variable-length
array (counted by an ``n_*`` field) is not a column (the Wi-Fi APs get their own table). A field
added to a ``.lcm`` file appears as a column without an edit here. Column dtypes follow the field
types: integers → int64, booleans → bool, strings → str, floating point → float64.

The pose channels are one table: ``POSE`` (the primary pose) and ``POSE_<SCHEME>`` (each fusion
scheme's, names generated from pose_t.lcm's schemes) are all ``pose_t`` and read into the ``POSE``
table, told apart by its ``scheme`` column as in logs from before the split (all schemes on POSE).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import stridefix
import stridefix_channels

_AXES = "xyz"


@dataclasses.dataclass(frozen=True)
class Channel:
    """One channel: its LCM type, its columns (name → numpy dtype) and the row function."""

    msg_type: Any  # a generated LCM class (decode(), __slots__)
    columns: dict[str, type]
    row: Callable[[Any], Any]  # message -> sequence of column values

    @property
    def names(self) -> list[str]:
        return list(self.columns)


def _element_names(field: str, n: int) -> list[str]:
    """Column names of a fixed-length array field: the axis goes before the unit."""
    axes = list(_AXES[:n]) if n <= len(_AXES) else [str(i) for i in range(n)]
    if "_" not in field:
        return [f"{field}_{a}" for a in axes]
    name, unit = field.rsplit("_", 1)
    return [f"{name}_{a}_{unit}" for a in axes]


def _dtype(value: Any) -> type:
    if isinstance(value, bool):
        return bool
    if isinstance(value, int):
        return np.int64
    if isinstance(value, str):
        return str
    return np.float64


def channel_of(msg_type: Any) -> Channel:
    """The columns and row function of an LCM type, from a default-constructed message's fields."""
    blank = msg_type()
    spec: list[tuple[str, int | None]] = []  # (field, array length or None for a scalar)
    columns: dict[str, type] = {}
    for field in msg_type.__slots__:
        value = getattr(blank, field)
        if isinstance(value, list):
            if not value:
                continue  # variable-length: not a column
            spec.append((field, len(value)))
            columns.update(dict.fromkeys(_element_names(field, len(value)), _dtype(value[0])))
        else:
            spec.append((field, None))
            columns[field] = _dtype(value)

    # The row function is compiled from the field list, as namedtuple builds its methods: it runs once
    # per message (IMU at 200 Hz), and a generic loop over the fields doubled the read time of a log.
    # The names are identifiers of the generated binding (__slots__), never user input.
    values = ", ".join(
        f"m.{field}" if n is None else ", ".join(f"m.{field}[{i}]" for i in range(n)) for field, n in spec
    )
    row = eval(f"lambda m: ({values},)", {})

    return Channel(msg_type, columns, row)


#: channel name → its Channel, from the one channel table (lcmtypes/channels.csv, generated into
#: stridefix_channels at build time); CONFIG is not a table: logread reads it into a dict
CHANNELS: dict[str, Channel] = {
    name: channel_of(getattr(stridefix, type_name))
    for name, type_name, _writer in stridefix_channels.CHANNELS
    if name != "CONFIG"
}
CONFIG_TYPE = stridefix.config_t

#: pose_t.SCHEME_* id of each fusion scheme → the channel of its own poses (POSE_EKF, ...), generated
POSE_SCHEME_CHANNELS: dict[int, str] = dict(stridefix_channels.POSE_SCHEME_CHANNELS)
#: the channel of the primary pose, and the table every pose channel is read into
POSE = "POSE"
#: every pose channel: POSE and the per-scheme ones
POSE_CHANNELS: frozenset[str] = frozenset((POSE, *POSE_SCHEME_CHANNELS.values()))


def table_of(channel: str) -> str:
    """The table a channel's messages go into: ``POSE`` for every pose channel, else its own."""
    return POSE if channel in POSE_CHANNELS else channel
