"""One look for every StrideFix report: the page's CSS and the figures' styles.

The walk report (``stridefix report``), realbench's page and ``stridefix compare`` take their CSS
and their truth / start / end / floor-plan styles from here; scheme colours come from the scheme
registry (:func:`stridefix_analyzer.schemes.scheme_colour`), the same in every plot.
"""

from __future__ import annotations

from typing import Any

CSS = """
body { font-family: system-ui, -apple-system, 'Segoe UI', sans-serif; margin: 2em auto;
       max-width: 1100px; color: #222; line-height: 1.4; padding: 0 1em; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { font-size: 1.2em; margin-top: 1.6em;
     border-bottom: 1px solid #ddd; padding-bottom: 0.2em; } h3 { font-size: 1.05em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }
th, td { border: 1px solid #ddd; padding: 0.25em 0.7em; text-align: right; }
th { background: #f4f4f4; } td.k, th.k { text-align: left; }
tr.primary td { font-weight: 600; background: #f3f8ff; }
.note { color: #666; font-size: 0.9em; } .warn { color: #a40; }
img { max-width: 100%; border: 1px solid #eee; margin: 0.4em 0; }
.figs { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; }
details > summary { cursor: pointer; color: #246; margin: 0.4em 0; }
"""

#: the truth path
TRUTH: dict[str, Any] = dict(color="black", linewidth=2.0, label="truth", zorder=3)
#: start and end of the truth, end of each scheme's track
START: dict[str, Any] = dict(
    marker="o", color="green", markersize=10, linestyle="none", label="start (truth)"
)
END: dict[str, Any] = dict(marker="X", color="red", markersize=10, linestyle="none", label="end (truth)")
POSE_END: dict[str, Any] = dict(marker="s", markersize=6, linestyle="none")
#: a scheme's track (its colour added), the primary scheme's a little heavier
TRACK: dict[str, Any] = dict(linewidth=1.0, alpha=0.85, zorder=2)
PRIMARY_LINEWIDTH = 1.8
#: floor plans: a bitmap under the tracks, or a site's walls as lines
PLAN_IMAGE: dict[str, Any] = dict(alpha=0.6, zorder=0)
WALL: dict[str, Any] = dict(color="#888", linewidth=1.0, zorder=1)
GRID: dict[str, Any] = dict(alpha=0.3)
#: a site's ports: a marker at the centre per kind (building.toml's names) and the disc it joins over
PORT: dict[str, dict[str, Any]] = {
    "door": dict(marker="D", color="#8c564b", markersize=7, linestyle="none", zorder=4),
    "stairs": dict(marker="^", color="#7a3db8", markersize=9, linestyle="none", zorder=4),
    "elevator": dict(marker="h", color="#1f6f8b", markersize=9, linestyle="none", zorder=4),
}
PORT_DISC: dict[str, Any] = dict(fill=False, linestyle="--", linewidth=0.8, alpha=0.7, zorder=1)
