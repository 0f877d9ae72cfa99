"""The multi-scheme controller's CONTEXT messages, summarised for ``metrics.json`` and the report.

The firmware publishes one ``context_t`` at every state change of its controller (the first
identification, a transition beginning at a port, the end of one; Jäger, Süß, Becker §III-C,
``firmware/core/sf_controller.h``). :func:`context_summary` turns the CONTEXT table and the last
HEALTH report into plain JSON:

* ``events`` and ``switches`` (messages with ``switched``), each by rule (rule names from the
  generated ``context_t.RULE_*`` constants: ``cls_unlimited``, ``near_port``, ``elevator``,
  ``stairs``, ``door``, ``left_port``);
* ``time_in_context_s``: seconds from each message to the next (the last one to ``end_us``, the log's
  last POSE) per context label (:func:`context_label`; ``none`` before the first identification);
* ``radios_on_s``: GNSS, Wi-Fi and BLE on-time [s] from the last HEALTH (the controller's policy),
  and HEALTH's ``context_transitions`` / ``_switches`` / ``_recalibrations``;
* ``rows``: every message (time since the first, rule, from → to, switched, the rule text with its
  evidence) for the report's table.

No site is read here: a context is labelled by what the message carries (kind, building index,
floor), e.g. ``outdoor``, ``building 0 floor 1``. Cost: O(n messages).
"""

from __future__ import annotations

import html
from collections.abc import Mapping
from typing import Any

import numpy as np
from stridefix import context_t

#: rule id → name, from context_t.RULE_* (a rule added to context_t.lcm is named without an edit here)
RULE_NAMES: dict[int, str] = dict(
    sorted((int(v), k[len("RULE_") :].lower()) for k, v in vars(context_t).items() if k.startswith("RULE_"))
)
#: HEALTH fields of the controller copied into the summary
_HEALTH_COUNTERS = ("context_transitions", "context_switches", "context_recalibrations")
#: radio → HEALTH field of its on-time [s]
RADIO_FIELDS: dict[str, str] = {"gnss": "gnss_on_s", "wifi": "wifi_on_s", "ble": "ble_on_s"}


def rule_name(code: int) -> str:
    """The name of rule id ``code`` (``rule_<code>`` for an id context_t does not define)."""
    return RULE_NAMES.get(int(code), f"rule_{int(code)}")


def context_label(kind: int, building: int, floor: int) -> str:
    """A context named from a CONTEXT message's fields (kind, building index, floor index)."""
    if kind == context_t.KIND_OUTDOOR:
        return "outdoor"
    if kind == context_t.KIND_BUILDING:
        return f"building {building}"
    if kind == context_t.KIND_FLOOR:
        return f"building {building} floor {floor}"
    return "none"


def _labels(ctx: Any) -> tuple[list[str], list[str]]:
    """Labels of the context after and before each message (the previous message's context)."""
    now = [
        context_label(int(k), int(b), int(f))
        for k, b, f in zip(ctx["kind"], ctx["building"], ctx["floor"], strict=True)
    ]
    return now, ["none", *now[:-1]]


def _by_rule(rules: np.ndarray) -> dict[str, int]:
    codes, counts = np.unique(np.asarray(rules, dtype=np.int64), return_counts=True)
    return {rule_name(int(c)): int(n) for c, n in zip(codes, counts, strict=True)}


def context_summary(ctx: Any, health: Mapping[str, Any], end_us: int | None = None) -> dict[str, Any] | None:
    """The ``context`` section of metrics.json (module docstring); None without CONTEXT messages.

    Parameters
    ----------
    ctx : Table or mapping of columns, or None
        The CONTEXT table (context_t fields as columns), sorted by ``t_us`` [µs].
    health : mapping
        The last HEALTH report's fields (``{}`` if none).
    end_us : int, optional
        End of the walk [µs] (the last POSE); default: the last message's time.
    """
    if ctx is None or len(ctx["t_us"]) == 0:
        return None
    t = np.asarray(ctx["t_us"], dtype=np.int64)
    switched = np.asarray(ctx["switched"]).astype(bool)
    rules = np.asarray(ctx["rule"], dtype=np.int64)
    now, before = _labels(ctx)
    end = max(int(t[-1]), int(end_us) if end_us is not None else int(t[-1]))
    spans = np.diff(np.append(t, end)) / 1e6
    time_in: dict[str, float] = {}
    for label, span in zip(now, spans, strict=True):
        time_in[label] = time_in.get(label, 0.0) + float(span)
    rows = [
        {
            "t_s": float((t[i] - t[0]) / 1e6),
            "t_us": int(t[i]),
            "rule": rule_name(int(rules[i])),
            "from": before[i],
            "to": now[i],
            "switched": bool(switched[i]),
            "text": str(ctx["rule_text"][i]),
        }
        for i in range(len(t))
    ]
    return {
        "events": int(len(t)),
        "switches": int(switched.sum()),
        "events_by_rule": _by_rule(rules),
        "switches_by_rule": _by_rule(rules[switched]),
        "time_in_context_s": dict(sorted(time_in.items())),
        "radios_on_s": {r: health.get(f) for r, f in RADIO_FIELDS.items()},
        **{k: health.get(k) for k in _HEALTH_COUNTERS},
        "rows": rows,
    }


def format_context_line(section: Mapping[str, Any] | None) -> str:
    """One console line about the controller's CONTEXT messages."""
    if not section:
        return "context: no CONTEXT message (no controller, or no context map in the site)"
    rules = ", ".join(f"{k} {v}" for k, v in section["switches_by_rule"].items()) or "none"
    radios = ", ".join(
        f"{name} {'-' if v is None else f'{v:.0f} s'}"
        for name, v in zip(("GNSS", "Wi-Fi", "BLE"), section["radios_on_s"].values(), strict=True)
    )
    final = section["rows"][-1]["to"]
    return (
        f"context: {section['events']} events, {section['switches']} switches ({rules}); "
        f"last context {final}; radios on: {radios}"
    )


def context_html(section: Mapping[str, Any] | None) -> str:
    """The report's table of CONTEXT events (time, rule, from → to, evidence), escaped."""
    if not section:
        return "<p class='note'>no CONTEXT message in the logs (no controller or no context map)</p>"
    head = (
        "<tr><th>t [s]</th><th class='k'>rule</th><th class='k'>from → to</th><th>switched</th>"
        "<th class='k'>evidence</th></tr>"
    )
    body = "".join(
        f"<tr><td>{r['t_s']:.1f}</td><td class='k'>{html.escape(r['rule'])}</td>"
        f"<td class='k'>{html.escape(r['from'])} → {html.escape(r['to'])}</td>"
        f"<td>{'yes' if r['switched'] else 'no'}</td><td class='k'>{html.escape(r['text'])}</td></tr>"
        for r in section["rows"]
    )
    radios = ", ".join(f"{k} {'–' if v is None else f'{v:.0f} s'}" for k, v in section["radios_on_s"].items())
    times = ", ".join(f"{k} {v:.0f} s" for k, v in section["time_in_context_s"].items())
    return (
        f"<p class='note'>{section['events']} events, {section['switches']} switches; time per context: "
        f"{html.escape(times)}; radios on (last HEALTH): {html.escape(radios)}</p>"
        f"<table>{head}{body}</table>"
    )
