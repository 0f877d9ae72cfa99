"""The walk report's configuration section: what differs from the defaults first, the rest folded.

The log's CONFIG (``metrics.json`` ``config.params``) is shown against the firmware's own params
table (``stridefixd --print-config --json``, :attr:`stridefix_analyzer.firmware.Firmware.params`:
default, unit, range, help), when that binary is at hand: the parameters whose value differs from
the default open, every parameter grouped by section in a folded ``<details>``, and an enumerated
parameter's value with its name. A value's name comes from the table's help text, the one source:
an integer parameter of at most :data:`MAX_ENUM_VALUES` values whose help names every one of them
as ``k = name`` (``0 = WkNN (…), 1 = Gaussian naive Bayes (…)`` → ``1 (Gaussian naive Bayes)``).
Without the binary the values are listed as logged.
"""

from __future__ import annotations

import html
import re
from collections.abc import Mapping, Sequence
from typing import Any

MAX_ENUM_VALUES = 4
_LABEL = re.compile(r"(?<![\w.])(\d+) = ([^,;()]+)")


def enum_names(p: Any) -> dict[int, str]:
    """value → name of an enumerated parameter (module docstring); empty when it is not one."""
    try:
        lo, hi = int(p.min), int(p.max)
    except (TypeError, ValueError):
        return {}
    if hi - lo + 1 > MAX_ENUM_VALUES or hi < lo:
        return {}
    names = {int(k): v.strip().rstrip(".") for k, v in _LABEL.findall(p.help or "")}
    if not all(v in names for v in range(lo, hi + 1)):
        return {}
    return {v: names[v][:40] for v in range(lo, hi + 1)}


def _firmware_params() -> Mapping[str, Any] | None:
    from stridefix_analyzer.firmware import Firmware, FirmwareError

    try:
        return Firmware().params
    except (FirmwareError, OSError):
        return None


def _shown(value: str, p: Any) -> str:
    names = enum_names(p) if p is not None else {}
    try:
        name = names.get(int(float(value))) if names else None
    except ValueError:
        name = None
    return f"{value} ({name})" if name else value


def _compact(value: Any) -> str:
    """A default as the log writes values: 5000 and 0.03, not 5000.0 (the shortest exact float text)."""
    try:
        f = float(value)
    except (TypeError, ValueError):
        return str(value)
    return str(int(f)) if f.is_integer() and abs(f) < 1e15 else repr(f)


def _differs(value: str, p: Any) -> bool:
    try:
        return float(value) != float(p.default)
    except (TypeError, ValueError):
        return str(value) != str(p.default)


def config_html(
    version_rows: Sequence[tuple[str, Any]], params: Mapping[str, str], table: Mapping[str, Any] | None = None
) -> str:
    """The section's HTML; ``table`` defaults to the firmware's (None when stridefixd is absent)."""
    if not params and not version_rows:
        return "<p class='note'>no CONFIG message in the logs</p>"
    table = _firmware_params() if table is None else table
    versions = "".join(
        f"<tr><td class='k'>{html.escape(str(k))}</td><td class='k'>{html.escape(str(v))}</td></tr>"
        for k, v in version_rows
    )
    parts = [f"<table>{versions}</table>"] if versions else []

    def row(key: str, value: str) -> str:
        p = (table or {}).get(key)
        default = _shown(_compact(p.default), p) if p is not None else "–"
        unit = html.escape(p.unit) if p is not None else ""
        return (
            f"<tr><td class='k'>{html.escape(key)}</td><td>{html.escape(_shown(value, p))}</td>"
            f"<td>{html.escape(default)}</td><td>{unit}</td></tr>"
        )

    head = "<tr><th class='k'>parameter</th><th>value</th><th>default</th><th>unit</th></tr>"
    keys = list(params)
    if table:
        changed = [k for k in keys if k in table and _differs(params[k], table[k])]
        unknown = [k for k in keys if k not in table]
        parts.append(
            f"<p class='note'>{len(keys)} parameters; {len(changed)} differ from this stridefixd's defaults"
            + (f", {len(unknown)} unknown to it (another version)" if unknown else "")
            + ".</p>"
        )
        if changed or unknown:
            parts.append(f"<table>{head}{''.join(row(k, params[k]) for k in changed + unknown)}</table>")
    else:
        parts.append(
            f"<p class='note'>{len(keys)} parameters (stridefixd not found: no defaults or names).</p>"
        )
    sections: dict[str, list[str]] = {}
    for k in keys:
        sections.setdefault(k.split(".", 1)[0], []).append(k)
    for sec, ks in sections.items():
        parts.append(
            f"<details><summary>{html.escape(sec)} ({len(ks)})</summary>"
            f"<table>{head}{''.join(row(k, params[k]) for k in ks)}</table></details>"
        )
    return "\n".join(parts)
