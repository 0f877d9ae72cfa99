"""The height of each floor [m], for the vertical part of the scores and the z of TUM exports.

A floor index becomes a height from, in this order:

1. a site file (``--site``): its ``floor_height_m`` table, the height of floors ``lowest_floor`` …
   ``lowest_floor + n − 1`` (increasing, site_t);
2. the log's CONFIG: ``floor.height_m``, the uniform floor-to-floor height stridefixd ran with (floor
   0 at z = 0), the number the estimator's own floor detection used;
3. otherwise the height is unknown: no vertical terms (``vertical`` is null), and a TUM export of a
   walk on more than one floor is refused (a one-floor walk is written with z = 0).

A floor outside a site's table continues from its nearest end at the uniform height of the CONFIG
(or the table's mean spacing when the log has no CONFIG; a one-floor table and no CONFIG leave it NaN).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

#: the CONFIG key of stridefixd's uniform floor-to-floor height (firmware/core/sf_params.h)
CONFIG_KEY = "floor.height_m"


class FloorHeightError(ValueError):
    """A floor-height source is unusable (the message names the file or key and the value)."""


@dataclasses.dataclass(frozen=True)
class FloorHeights:
    """Floor index → height [m]; ``source`` says where the numbers came from (for reports)."""

    source: str
    spacing_m: float  # uniform floor-to-floor height outside (or without) a table; NaN when unknown
    lowest_floor: int = 0
    table_m: tuple[float, ...] = ()  # heights of lowest_floor, lowest_floor + 1, …

    @property
    def known(self) -> bool:
        return bool(self.table_m) or bool(np.isfinite(self.spacing_m))

    def z_m(self, floor: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Heights [m] of the floors ``floor`` (any shape)."""
        f = np.asarray(floor, dtype=np.int64)
        if not self.table_m:
            return f.astype(np.float64) * self.spacing_m
        table = np.asarray(self.table_m, dtype=np.float64)
        i = f - self.lowest_floor
        inside = (i >= 0) & (i < table.size)
        z = np.where(inside, table[np.clip(i, 0, table.size - 1)], np.nan)
        below, above = i < 0, i >= table.size
        z = np.where(below, table[0] + i * self.spacing_m, z)
        return np.where(above, table[-1] + (i - table.size + 1) * self.spacing_m, z)


def from_config(config: Mapping[str, str]) -> FloorHeights | None:
    """The uniform height of a log's CONFIG (``LogData.config``), or None when it has none."""
    raw = config.get(CONFIG_KEY)
    if raw is None:
        return None
    try:
        h = float(raw)
    except ValueError as exc:
        raise FloorHeightError(f"CONFIG {CONFIG_KEY} = {raw!r}: not a number") from exc
    if not (np.isfinite(h) and h > 0):
        raise FloorHeightError(f"CONFIG {CONFIG_KEY} = {raw!r}: must be a positive height [m]")
    return FloorHeights(source=f"CONFIG {CONFIG_KEY} = {h:g} m", spacing_m=h)


def read_site_for_scoring(path: str | os.PathLike[str]) -> Any:
    """The site file ``analyze --site`` names (its floor heights and walls), errors as
    :class:`FloorHeightError`."""
    from stridefix_analyzer.io.sitefile import SiteFileError, read_site  # LCM bindings only when needed

    try:
        site = read_site(path)
    except SiteFileError as exc:
        raise FloorHeightError(str(exc)) from exc
    if not len(site.floor_height_m):
        raise FloorHeightError(f"{path}: the site has no floor_height_m table")
    return site


def from_table(
    table_m: Sequence[float], lowest_floor: int, source: str, config: Mapping[str, str] | None = None
) -> FloorHeights:
    """A site's table (heights of ``lowest_floor`` …); outside it, the CONFIG's uniform height, else
    the table's mean spacing (module docstring). ``source`` names where the table is from."""
    table = tuple(float(h) for h in table_m)
    uniform = from_config(config or {})
    spacing = uniform.spacing_m if uniform else (float(np.mean(np.diff(table))) if len(table) > 1 else np.nan)
    return FloorHeights(
        source=f"{source} (floors {lowest_floor}..{lowest_floor + len(table) - 1})",
        spacing_m=spacing,
        lowest_floor=int(lowest_floor),
        table_m=table,
    )


def resolve(config: Mapping[str, str], site: Any = None, site_name: str = "") -> FloorHeights:
    """The heights to use (module docstring's order): ``site`` (a site_t, e.g. from
    :func:`read_site_for_scoring`) named ``site_name``, else the CONFIG; ``known`` is False when
    there are none."""
    if site is not None:
        return from_table(site.floor_height_m, site.lowest_floor, f"site {site_name}", config)
    return from_config(config) or FloorHeights(source="unknown (no site, no CONFIG)", spacing_m=float("nan"))
