"""Which source each fix came from: FIX records counted per scheme and per method.

Every absolute fix the firmware offers (a Wi-Fi fingerprint, a GNSS receiver fix, a BLE beacon fix,
a landmark) gets one FIX record per scheme with its verdict. :func:`fix_source_counts` counts them
per scheme and per method: ``offered`` (records), ``accepted``, ``rejected`` and
``rejected_by_reason`` (reason name → records). Method and reason names come from the generated
``stridefix.fix_t`` constants (``METHOD_WIFI`` → ``wifi``, ``REASON_GATE`` → ``gate``), scheme names
from :mod:`stridefix_analyzer.schemes`, so a method or reason added to ``fix_t.lcm`` is counted
without an edit here. The counts are plain JSON (``metrics.json``: ``fix_sources``; realbench:
per walk and pooled per group); :func:`merge_fix_source_counts` pools them and
:func:`fix_source_rows` lays them out as table rows for the consoles and HTML reports.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from stridefix import fix_t

from stridefix_analyzer.schemes import NAMES, scheme_name


def _constants(prefix: str) -> dict[int, str]:
    return {int(v): k[len(prefix) :].lower() for k, v in vars(fix_t).items() if k.startswith(prefix)}


#: method id → name, in id order (fix_t.METHOD_*)
METHOD_NAMES: dict[int, str] = dict(sorted(_constants("METHOD_").items()))
#: reason id → name (fix_t.REASON_*)
REASON_NAMES: dict[int, str] = dict(sorted(_constants("REASON_").items()))
#: how the reports title a method
METHOD_LABELS: dict[str, str] = {"wifi": "Wi-Fi", "gnss": "GNSS", "ble": "BLE", "landmark": "landmark"}


def method_name(code: int) -> str:
    """The name of method id ``code`` (``method_<code>`` for an id fix_t does not define)."""
    return METHOD_NAMES.get(int(code), f"method_{int(code)}")


def reason_name(code: int) -> str:
    """The name of reason id ``code`` (``reason_<code>`` for an id fix_t does not define)."""
    return REASON_NAMES.get(int(code), f"reason_{int(code)}")


def method_label(name: str) -> str:
    """The method's title in reports (``Wi-Fi``, ``GNSS``, ``BLE``, ``landmark``; else the name)."""
    return METHOD_LABELS.get(name, name)


def _empty() -> dict[str, Any]:
    return {"offered": 0, "accepted": 0, "rejected": 0, "rejected_by_reason": {}}


def fix_source_counts(fix: Any) -> dict[str, dict[str, dict[str, Any]]]:
    """Counts of a FIX table (:class:`~stridefix_analyzer.io.logread.Table` or a mapping of columns
    with ``scheme``, ``method``, ``accepted`` and ``reason``): scheme name → method name →
    ``{"offered", "accepted", "rejected", "rejected_by_reason"}``. Schemes and methods without a
    record are left out; None or an empty table gives ``{}``."""
    if fix is None or len(fix["scheme"]) == 0:
        return {}
    scheme = np.asarray(fix["scheme"], dtype=np.int64)
    method = np.asarray(fix["method"], dtype=np.int64)
    accepted = np.asarray(fix["accepted"]).astype(bool)
    reason = np.asarray(fix["reason"], dtype=np.int64)
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for s in np.unique(scheme):
        per: dict[str, dict[str, Any]] = {}
        for m in np.unique(method[scheme == s]):
            sel = (scheme == s) & (method == m)
            rejected = reason[sel & ~accepted]
            codes, counts = np.unique(rejected, return_counts=True)
            per[method_name(int(m))] = {
                "offered": int(sel.sum()),
                "accepted": int((sel & accepted).sum()),
                "rejected": int(rejected.size),
                "rejected_by_reason": {
                    reason_name(int(c)): int(n) for c, n in zip(codes, counts, strict=True)
                },
            }
        out[scheme_name(int(s))] = dict(sorted(per.items(), key=lambda kv: _method_order(kv[0])))
    return dict(sorted(out.items(), key=lambda kv: _scheme_order(kv[0])))


def merge_fix_source_counts(
    counts: Iterable[Mapping[str, Mapping[str, Mapping[str, Any]]]],
) -> dict[str, dict[str, dict[str, Any]]]:
    """The sum of several :func:`fix_source_counts` results (the walks of a group)."""
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for c in counts:
        for s, per in c.items():
            for m, v in per.items():
                acc = out.setdefault(s, {}).setdefault(m, _empty())
                for key in ("offered", "accepted", "rejected"):
                    acc[key] += int(v[key])
                for r, n in v["rejected_by_reason"].items():
                    acc["rejected_by_reason"][r] = acc["rejected_by_reason"].get(r, 0) + int(n)
    return {
        s: dict(sorted(per.items(), key=lambda kv: _method_order(kv[0])))
        for s, per in sorted(out.items(), key=lambda kv: _scheme_order(kv[0]))
    }


def fix_source_rows(counts: Mapping[str, Mapping[str, Mapping[str, Any]]]) -> list[list[str]]:
    """Table rows (scheme, method, offered, accepted, rejected, rejected by reason) of the counts."""
    rows = []
    for s, per in counts.items():
        for m, v in per.items():
            reasons = ", ".join(f"{r} {n}" for r, n in sorted(v["rejected_by_reason"].items())) or "-"
            rows.append(
                [s, method_label(m), str(v["offered"]), str(v["accepted"]), str(v["rejected"]), reasons]
            )
    return rows


FIX_SOURCE_HEADER = ["scheme", "source", "offered", "accepted", "rejected", "rejected by reason"]


def _method_order(name: str) -> int:
    ids = {n: i for i, n in METHOD_NAMES.items()}
    return ids.get(name, 1 << 30)


def _scheme_order(name: str) -> int:
    return NAMES.index(name) if name in NAMES else len(NAMES)


def format_fix_sources(counts: Mapping[str, Mapping[str, Mapping[str, Any]]], where: str = "") -> str:
    """A plain-text table of the counts (the consoles; ``where`` is added to its title, e.g. "pooled
    over the walks"); one line saying so when there is no FIX."""
    rows = fix_source_rows(counts)
    if not rows:
        return "fix sources: no FIX record"
    widths = [max(len(r[i]) for r in [FIX_SOURCE_HEADER, *rows]) for i in range(len(FIX_SOURCE_HEADER))]
    lines = [f"fix sources (FIX records per scheme and source{', ' + where if where else ''}):"]
    for r in [FIX_SOURCE_HEADER, *rows]:
        cells = [r[0].ljust(widths[0]), r[1].ljust(widths[1])]
        cells += [r[i].rjust(widths[i]) for i in (2, 3, 4)]
        cells.append(r[5])
        lines.append("  " + "  ".join(cells))
    return "\n".join(lines)


def fix_sources_html(counts: Mapping[str, Mapping[str, Mapping[str, Any]]]) -> str:
    """The counts as an HTML table (escaped); a note when there is no FIX."""
    rows = fix_source_rows(counts)
    if not rows:
        return "<p class='note'>no FIX record in the logs</p>"
    head = "".join(f"<th>{html.escape(h)}</th>" for h in FIX_SOURCE_HEADER)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><tr>{head}</tr>{body}</table>"
