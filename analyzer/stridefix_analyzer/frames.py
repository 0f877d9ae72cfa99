"""StrideFix logs as pandas DataFrames, one per channel, for notebooks and scripts.

:func:`read_frames` reads LCM logs with the analyzer's own reader
(:func:`stridefix_analyzer.io.logread.read_logs`) and turns each :class:`~stridefix_analyzer.io.logread.Table`
into a DataFrame with the same columns in the same order and the same rows (sorted by ``t_us``), plus:

* ``t_s``: the message's board time in seconds (``t_us`` / 10⁶), for plots; ``t_us`` stays, exact;
* ``scheme_name`` beside every ``scheme`` column (POSE, FIX): the scheme's name from the registry
  (``pdr_only``, ``ekf``, ...), so ``df.groupby("scheme_name")`` reads as the reports do.

Channels and columns are those of :mod:`stridefix_analyzer.io.logread` (every pose channel is one
``POSE`` frame, told apart by ``scheme``; the Wi-Fi APs are ``WIFI_AP``, with ``scan_row`` the row of
their scan in ``WIFI``). An example, run by the tests::

    from stridefix_analyzer.frames import read_frames

    frames = read_frames(["out/demo/stridefixd.lcmlog"])
    pose = frames["POSE"]
    print(pose.groupby("scheme_name")["sigma_m"].mean())

pandas is part of the ``export`` extra (``pip install 'stridefix[export]'``; ``make deps`` installs it).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from stridefix_analyzer.io.logread import LogData, LogTruncatedWarning, Table, read_logs
from stridefix_analyzer.schemes import NAMES, scheme_name

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["read_frames", "to_frame"]

#: what to run when pandas is missing
INSTALL_HINT = "pip install 'stridefix[export]' (in a checkout: make deps)"


def _pandas() -> Any:
    try:
        import pandas
    except ImportError:
        raise ImportError(f"stridefix_analyzer.frames needs pandas: {INSTALL_HINT}") from None
    return pandas


def to_frame(table: Table) -> pd.DataFrame:
    """One :class:`Table` as a DataFrame: its columns in order, ``t_s`` after ``t_us`` and
    ``scheme_name`` after ``scheme`` when the table has them (module docstring)."""
    pandas = _pandas()
    columns: dict[str, Any] = {}
    for name in table.names:
        columns[name] = table[name]
        if name == "t_us":
            columns["t_s"] = table[name] * 1e-6
        elif name == "scheme":
            names = [scheme_name(c) for c in table[name]]
            # categories in the registry's (report) order, then any id pose_t.lcm does not name
            order = [n for n in NAMES if n in set(names)] + sorted(set(names) - set(NAMES))
            columns["scheme_name"] = pandas.Categorical(names, categories=order)
    return pandas.DataFrame(columns)


def read_frames(
    paths: Iterable[str | os.PathLike[str]],
    channels: Iterable[str] | None = None,
    *,
    log: LogData | None = None,
) -> dict[str, pd.DataFrame]:
    """Read LCM logs into one DataFrame per channel.

    Parameters
    ----------
    paths : iterable of str or path
        One or more LCM event logs (e.g. stridefixd's log and the simulator's truth log); merged as
        :func:`~stridefix_analyzer.io.logread.read_logs` merges them.
    channels : iterable of str, optional
        Channels to decode (default: all; naming few is faster on long logs). ``POSE`` (or any
        ``POSE_<SCHEME>``) reads every pose channel into the one ``POSE`` frame.
    log : LogData, optional
        An already-read :class:`~stridefix_analyzer.io.logread.LogData` to convert instead of
        reading ``paths`` again.

    Returns
    -------
    dict of str to pandas.DataFrame
        Table name (``POSE``, ``STEP``, ``FIX``, ``IMU``, ``WIFI``, ``WIFI_AP``, ``TRUTH``, ...) → its
        frame; only channels that had messages.

    Raises
    ------
    LogReadError
        A file is missing, unreadable or not an LCM log (the message names it).
    ImportError
        pandas is not installed (the message says what to install).
    """
    _pandas()
    if log is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)  # a cut-short log reads up to its end
            log = read_logs(paths, decode=channels)
    return {name: to_frame(table) for name, table in log.tables.items()}
