"""Walk-mode radio maps as sufficient statistics that add and subtract (leave-one-walk-out maps).

:class:`WalkStats` holds the per-cell and per-(cell, AP) sums a walk-mode map is a function of, so
the map of all recordings but one is ``total - that one``; :meth:`WalkStats.to_site` gives the site
:func:`~.build.build_site` would build from the same recordings in walk mode.
"""

from __future__ import annotations

import math

import numpy as np
from stridefix import site_t

from stridefix_analyzer.radiomap.assemble import (
    DEFAULT_FLOOR_HEIGHT_M,
    DEFAULT_MIN_COUNT,
    TOOL_VERSION,
    assemble_site,
    site_summary,
)
from stridefix_analyzer.radiomap.grid import DEFAULT_CELL_SIZE_M, group_sum, row_codes
from stridefix_analyzer.radiomap.placement import (
    DEFAULT_SCAN_DURATION_MS,
    DEFAULT_STATIC_TOL_M,
    ap_rows,
    collect_scans,
)
from stridefix_analyzer.radiomap.recordings import RadioMapInputError, Recording


class WalkStats:
    """Sufficient statistics of a walk-mode radio map, which add and subtract.

    A walk-mode map is a function of per-cell and per-(cell, AP) sums, so the map of a set of
    recordings is the sum of their statistics, and the map of all recordings but one is
    ``total - that one`` (leave one walk out without rebuilding). Counts are integers and RSSI sums
    of integer dBm are exact in float64, so subtraction gives the same entries as a build from
    scratch; position sums differ from it by rounding only (~1e-12 m).

    Attributes
    ----------
    cell_size_m : float
        Grid cell [m].
    cell_key : (c, 3) int64
        (floor, iy, ix) of each cell, sorted lexicographically (= the RP order of :func:`build_site`).
    cell_scans : (c,) int64
        Scans placed in the cell.
    cell_sum_xy_m : (c, 2) float64
        Σx, Σy of those scans' positions [m].
    entry_key : (e, 4) int64
        (floor, iy, ix, BSSID), sorted.
    entry_count : (e,) int64
        Scans of the cell that heard the AP (once per scan, strongest reading).
    entry_sum_dbm, entry_sum2_dbm2 : (e,) float64
        Σ RSSI [dBm] and Σ RSSI² [dBm²] over those scans.
    scans : dict
        ``total``, ``used`` and ``skipped_<reason>`` counts (add and subtract like the rest).
    """

    def __init__(
        self,
        cell_size_m,
        cell_key,
        cell_scans,
        cell_sum_xy_m,
        entry_key,
        entry_count,
        entry_sum_dbm,
        entry_sum2_dbm2,
        scans,
    ):
        self.cell_size_m = float(cell_size_m)
        self.cell_key, self.cell_scans, self.cell_sum_xy_m = cell_key, cell_scans, cell_sum_xy_m
        self.entry_key, self.entry_count = entry_key, entry_count
        self.entry_sum_dbm, self.entry_sum2_dbm2 = entry_sum_dbm, entry_sum2_dbm2
        self.scans = dict(scans)

    @classmethod
    def from_recordings(
        cls,
        recordings: list[Recording],
        cell_size_m: float = DEFAULT_CELL_SIZE_M,
        scan_duration_ms: float = DEFAULT_SCAN_DURATION_MS,
        static_tol_m: float = DEFAULT_STATIC_TOL_M,
    ) -> "WalkStats":
        """Statistics of ``recordings`` placed and deduplicated exactly as :func:`build_site` does
        in walk mode. A recording with no placeable scan contributes nothing (no error)."""
        if not (cell_size_m > 0 and math.isfinite(cell_size_m)):
            raise RadioMapInputError(f"cell size {cell_size_m} m must be > 0")
        placed = collect_scans(recordings, scan_duration_ms, static_tol_m)
        ok = placed["ok"]
        x, y, floor = placed["x_m"], placed["y_m"], placed["floor"]
        key = np.zeros((len(x), 3), dtype=np.int64)
        key[ok] = np.stack(
            [
                floor[ok],
                np.floor(y[ok] / cell_size_m).astype(np.int64),
                np.floor(x[ok] / cell_size_m).astype(np.int64),
            ],
            axis=1,
        )
        cell_key, cell_vals = group_sum(key[ok], np.column_stack([np.ones(int(ok.sum())), x[ok], y[ok]]))
        a_scan, a_bssid, a_rssi, _, _ = ap_rows(placed, ok)
        ekey = np.column_stack([key[a_scan], a_bssid]) if len(a_scan) else np.zeros((0, 4), np.int64)
        entry_key, evals = group_sum(ekey, np.column_stack([np.ones(len(a_rssi)), a_rssi, a_rssi**2]))
        scans = {
            "total": placed["n_total"],
            "used": int(ok.sum()),
            **{f"skipped_{k}": v for k, v in placed["skipped"].items() if k != "moving"},
        }
        return cls(
            cell_size_m,
            cell_key,
            np.rint(cell_vals[:, 0]).astype(np.int64),
            cell_vals[:, 1:].copy(),
            entry_key,
            np.rint(evals[:, 0]).astype(np.int64),
            evals[:, 1].copy(),
            evals[:, 2].copy(),
            scans,
        )

    @classmethod
    def empty(cls, cell_size_m: float = DEFAULT_CELL_SIZE_M) -> "WalkStats":
        return cls(
            cell_size_m,
            np.zeros((0, 3), np.int64),
            np.zeros(0, np.int64),
            np.zeros((0, 2)),
            np.zeros((0, 4), np.int64),
            np.zeros(0, np.int64),
            np.zeros(0),
            np.zeros(0),
            {},
        )

    @classmethod
    def total(cls, parts: list["WalkStats"]) -> "WalkStats":
        """The sum of many statistics at once (one sort instead of one per addition)."""
        if not parts:
            raise RadioMapInputError("no radio-map statistics to add")
        acc = cls(
            parts[0].cell_size_m,
            np.concatenate([p.cell_key for p in parts]),
            np.concatenate([p.cell_scans for p in parts]),
            np.concatenate([p.cell_sum_xy_m for p in parts]),
            np.concatenate([p.entry_key for p in parts]),
            np.concatenate([p.entry_count for p in parts]),
            np.concatenate([p.entry_sum_dbm for p in parts]),
            np.concatenate([p.entry_sum2_dbm2 for p in parts]),
            {},
        )
        if any(p.cell_size_m != acc.cell_size_m for p in parts):
            raise RadioMapInputError("cannot add radio-map statistics of different cell sizes")
        out = acc._combine(cls.empty(acc.cell_size_m), +1)
        out.scans = {k: sum(p.scans.get(k, 0) for p in parts) for k in set().union(*(p.scans for p in parts))}
        return out

    def _combine(self, other: "WalkStats", sign: int) -> "WalkStats":
        if other.cell_size_m != self.cell_size_m:
            raise RadioMapInputError(
                f"cannot combine radio-map statistics of cell "
                f"{self.cell_size_m:g} m and {other.cell_size_m:g} m"
            )
        ck, cv = group_sum(
            np.concatenate([self.cell_key, other.cell_key]),
            np.concatenate(
                [
                    np.column_stack([self.cell_scans, self.cell_sum_xy_m]),
                    sign * np.column_stack([other.cell_scans, other.cell_sum_xy_m]),
                ]
            ),
        )
        ek, ev = group_sum(
            np.concatenate([self.entry_key, other.entry_key]),
            np.concatenate(
                [
                    np.column_stack([self.entry_count, self.entry_sum_dbm, self.entry_sum2_dbm2]),
                    sign * np.column_stack([other.entry_count, other.entry_sum_dbm, other.entry_sum2_dbm2]),
                ]
            ),
        )
        c_n, e_n = np.rint(cv[:, 0]).astype(np.int64), np.rint(ev[:, 0]).astype(np.int64)
        if (c_n < 0).any() or (e_n < 0).any():
            raise RadioMapInputError("radio-map statistics: subtracted more than the total holds")
        c_keep, e_keep = c_n > 0, e_n > 0
        scans = {
            k: self.scans.get(k, 0) + sign * other.scans.get(k, 0) for k in set(self.scans) | set(other.scans)
        }
        return WalkStats(
            self.cell_size_m,
            ck[c_keep],
            c_n[c_keep],
            cv[c_keep, 1:],
            ek[e_keep],
            e_n[e_keep],
            ev[e_keep, 1],
            ev[e_keep, 2],
            scans,
        )

    def __add__(self, other: "WalkStats") -> "WalkStats":
        return self._combine(other, +1)

    def __sub__(self, other: "WalkStats") -> "WalkStats":
        """``self`` without ``other``, which must be part of it (e.g. total − one walk)."""
        return self._combine(other, -1)

    def to_site(
        self,
        min_count: int = DEFAULT_MIN_COUNT,
        name: str = "",
        map_rotation_deg: float = 0.0,
        floor_height_m: float = DEFAULT_FLOOR_HEIGHT_M,
        floor_heights_m=None,
        lowest_floor: int | None = None,
        origin_deg: tuple[float, float] | None = None,
        source: str = "",
    ) -> tuple[site_t, dict]:
        """The walk-mode site of these statistics, as :func:`build_site` would build it from the
        same recordings; returns (site, summary)."""
        if min_count < 1:
            raise RadioMapInputError(f"min count {min_count} must be >= 1")
        if len(self.cell_key) == 0:
            raise RadioMapInputError("no scan could be placed on the truth (empty statistics)")
        n = self.cell_scans
        rp_x, rp_y = self.cell_sum_xy_m[:, 0] / n, self.cell_sum_xy_m[:, 1] / n
        rp_floor = self.cell_key[:, 0].copy()
        # entry -> RP index: entry keys are sorted by (floor, iy, ix, bssid), cells by (f, iy, ix)
        cell_code = row_codes(self.cell_key)
        rp = np.searchsorted(cell_code, row_codes(self.entry_key[:, :3]))
        keys = np.column_stack([self.entry_key[:, 3], rp])
        order = np.lexsort((keys[:, 1], keys[:, 0]))
        keys = keys[order]
        count = self.entry_count[order]
        mean = self.entry_sum_dbm[order] / count
        var = np.maximum(self.entry_sum2_dbm2[order] / count - mean**2, 0.0)
        site, kept, has_entry = assemble_site(
            keys,
            count,
            mean,
            np.sqrt(var),
            rp_x,
            rp_y,
            rp_floor,
            n.copy(),
            min_count=min_count,
            source=source
            or f"stridefix {TOOL_VERSION}: walk mode from sufficient statistics; "
            f"cell {self.cell_size_m:g} m; min count {min_count}",
            name=name,
            map_rotation_deg=map_rotation_deg,
            cell_size_m=self.cell_size_m,
            floor_height_m=floor_height_m,
            floor_heights_m=floor_heights_m,
            lowest_floor=lowest_floor,
            origin_deg=origin_deg,
        )
        summary = site_summary(site)
        summary.update(
            mode="walk",
            mode_reason="sufficient statistics",
            scans=dict(self.scans),
            entries_below_min_count=int(np.sum(~kept)),
            min_count=min_count,
            rps_dropped_no_entry=int(np.sum(~has_entry)),
        )
        return site, summary
