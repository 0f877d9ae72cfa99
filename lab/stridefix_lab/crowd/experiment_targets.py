"""The targets of ``crowd experiment --msindoor``: on each floor, the graph's solved positions
≥ 20 % better (mean error at the non-anchor waypoints) than interpolating the anchors in time."""

from __future__ import annotations

from typing import Any

#: graph mean error ≤ this × anchor interpolation's
GRAPH_VS_INTERP_MAX = 0.80


def solve_targets(floors: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One target row per floor (``{"figure", "value", "target", "met"}``, as scoring/targets.py)."""
    out = []
    for f in floors:
        rows = {r["key"]: r for r in f["rows"]}
        g, a = rows.get("graph", {}).get("mean_m"), rows.get("anchors_interp", {}).get("mean_m")
        ratio = g / a if g is not None and a else None
        out.append(
            {
                "figure": f"{f['floor']} graph / anchor interpolation mean error ({g:.2f} / {a:.2f} m)"
                if ratio is not None
                else f"{f['floor']} graph / anchor interpolation mean error",
                "value": ratio,
                "target": f"<= {GRAPH_VS_INTERP_MAX:.2f}",
                "met": ratio is not None and ratio <= GRAPH_VS_INTERP_MAX,
            }
        )
    return out
