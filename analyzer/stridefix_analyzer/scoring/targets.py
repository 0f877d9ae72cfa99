"""The console form of a bench's targets (the rows ``{"figure", "value", "target", "met"}`` its JSON
holds): the MET/MISSED table, and the ``TARGET MISSED`` lines the bench runner prints for ``make bench``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any


def table_lines(targets: Sequence[dict[str, Any]]) -> list[str]:
    """``targets:`` and one line per target: MET or MISSED, the figure, its value and the target."""
    lines = ["targets:"]
    for tg in targets:
        v = tg["value"]
        vs = "n/a" if v is None else (f"{v:.3f}" if isinstance(v, float) else str(v))
        lines.append(f"  {'MET   ' if tg['met'] else 'MISSED'} {tg['figure']} = {vs} (target {tg['target']})")
    return lines


def missed_lines(bench: str, targets: Sequence[dict[str, Any]]) -> list[str]:
    """One line per missed target: the bench's name, the figure, its value and the target."""
    return [
        f"{bench}: {tg['figure']} = {'n/a' if tg['value'] is None else tg['value']} (target {tg['target']})"
        for tg in targets
        if not tg["met"]
    ]
