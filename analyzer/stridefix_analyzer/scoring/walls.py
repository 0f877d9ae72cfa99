"""The site's floor plan against a track: how often a track passes through a wall.

A person walks through doorways, never through a wall, so every wall a track crosses is an error the
truth is not needed to see: the count is a map-consistency figure for any walk on a site with walls
(the map-aware particle filter kills the particles that cross one; the other schemes do not look).
A crossing is a pair of consecutive samples on the same floor whose straight segment intersects a
wall segment of that floor: a segment that ends on a wall counts, one that starts on it does not (a
track stepping onto a wall and on through it is one crossing, not two); a pair on two floors (a floor
change) is never one; parallel overlap is none.

Also the site's walls and ports as the named arrays the report draws (``site_wall_*``,
``site_port_*`` in ``analysis.npz``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from stridefix import site_t

#: port kind (site_t.PORT_*) → its name, as building.toml spells it
PORT_KINDS = {site_t.PORT_DOOR: "door", site_t.PORT_STAIRS: "stairs", site_t.PORT_ELEVATOR: "elevator"}


def wall_array(site: Any) -> npt.NDArray[np.float64]:
    """The site's walls as an (n_walls, 5) array of x0, y0, x1, y1 [m] and floor."""
    cols = [site.wall_x0_m, site.wall_y0_m, site.wall_x1_m, site.wall_y1_m, site.wall_floor]
    return np.column_stack([np.asarray(c, np.float64) for c in cols]).reshape(-1, 5)


def crossings(x_m: npt.ArrayLike, y_m: npt.ArrayLike, floor: npt.ArrayLike, walls: np.ndarray) -> int:
    """The consecutive sample pairs of a track (time order) on one floor whose segment crosses a
    wall of that floor (module docstring). ``walls`` is :func:`wall_array`'s (n, 5)."""
    x, y, f = (np.asarray(a) for a in (x_m, y_m, floor))
    if len(x) < 2 or len(walls) == 0:
        return 0
    same = (
        (f[:-1] == f[1:])
        & np.isfinite(x[:-1])
        & np.isfinite(x[1:])
        & np.isfinite(y[:-1])
        & np.isfinite(y[1:])
    )
    n = 0
    for fl in np.unique(f[:-1][same]):
        w = walls[walls[:, 4] == fl]
        k = np.flatnonzero(same & (f[:-1] == fl))
        if len(w) == 0 or len(k) == 0:
            continue
        # segment p + t·r (the track's) against q + u·s (a wall's), all pairs at once
        px, py = x[k][:, None], y[k][:, None]
        rx, ry = (x[k + 1] - x[k])[:, None], (y[k + 1] - y[k])[:, None]
        qx, qy = w[:, 0][None, :], w[:, 1][None, :]
        sx, sy = (w[:, 2] - w[:, 0])[None, :], (w[:, 3] - w[:, 1])[None, :]
        den = rx * sy - ry * sx
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((qx - px) * sy - (qy - py) * sx) / den
            u = ((qx - px) * ry - (qy - py) * rx) / den
        hit = (den != 0) & (t > 0) & (t <= 1) & (u >= 0) & (u <= 1)
        n += int(np.count_nonzero(hit.any(axis=1)))
    return n


def plan_series(site: Any) -> dict[str, np.ndarray]:
    """The site's walls (``site_wall_x0_m`` … ``site_wall_floor``) and ports (``site_port_kind``,
    ``_x_m``, ``_y_m``, ``_radius_m``, ``_floor_lo``, ``_floor_hi``) as arrays for ``analysis.npz``."""
    out: dict[str, np.ndarray] = {}
    for col in ("x0_m", "y0_m", "x1_m", "y1_m"):
        out[f"site_wall_{col}"] = np.asarray(getattr(site, f"wall_{col}"), np.float64)
    out["site_wall_floor"] = np.asarray(site.wall_floor, np.int64)
    for col in ("x_m", "y_m", "radius_m"):
        out[f"site_port_{col}"] = np.asarray(getattr(site, f"port_{col}"), np.float64)
    for col in ("kind", "floor_lo", "floor_hi"):
        out[f"site_port_{col}"] = np.asarray(getattr(site, f"port_{col}"), np.int64)
    return out
