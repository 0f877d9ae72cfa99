"""Walk-mode gridding: scans go to the grid cell ``(floor, ⌊y/cell⌋, ⌊x/cell⌋)`` of the map frame.

Cells are ordered by (floor, iy, ix): :func:`walk_cells` numbers them so, :func:`row_codes` packs a
(floor, iy, ix) row into one order-preserving integer, and :func:`group_sum` sums values per unique
key row in that order (the sufficient statistics of :class:`~.walkstats.WalkStats`).
"""

from __future__ import annotations

import numpy as np

DEFAULT_CELL_SIZE_M = 2.0


def walk_cells(x, y, floor, cell_m: float) -> np.ndarray:
    """Cell id per scan, ids ordered by (floor, iy, ix)."""
    key = np.stack(
        [floor, np.floor(y / cell_m).astype(np.int64), np.floor(x / cell_m).astype(np.int64)], axis=1
    )
    _, ids = np.unique(key, axis=0, return_inverse=True)
    return ids.reshape(-1)


def row_codes(rows: np.ndarray) -> np.ndarray:
    """A sortable code per (floor, iy, ix) row, order-preserving (lexicographic)."""
    r = rows.astype(np.int64)
    return ((r[:, 0] + (1 << 15)) << 42) + ((r[:, 1] + (1 << 20)) << 21) + (r[:, 2] + (1 << 20))


def group_sum(keys: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``keys`` (n, k) int64 made unique (sorted lexicographically, as ``np.unique(...,
    axis=0)`` sorts them) and ``values`` (n, m) summed per unique row."""
    if len(keys) == 0:
        return keys.reshape(0, keys.shape[1]), values.reshape(0, values.shape[1])
    # (floor, iy, ix) packed into one order-preserving code: fewer sort keys
    cols = (
        [row_codes(keys[:, :3])] + [keys[:, j] for j in range(3, keys.shape[1])]
        if keys.shape[1] >= 3
        else [keys[:, j] for j in range(keys.shape[1])]
    )
    order = np.lexsort(cols[::-1])
    sorted_cols = [c[order] for c in cols]
    diff = np.zeros(len(order), dtype=bool)
    diff[0] = True
    for c in sorted_cols:
        diff[1:] |= c[1:] != c[:-1]
    first = np.flatnonzero(diff)
    return keys[order[first]], np.add.reduceat(values[order], first, axis=0)
