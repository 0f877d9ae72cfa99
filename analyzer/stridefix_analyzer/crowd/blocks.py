"""The pair-block work of the streaming binned fit as independent tasks, merged in a fixed order.

:func:`bin_pairs` streams every unordered scan pair (i > j) of a group (floor) through blocks of
``block`` × ``block`` scans; here each block pair (group, i0, j0) is a task that returns its own
partial :class:`.model.PairBins`, and :func:`merge_bins` adds the partials in task order (group, then
i0, then j0 — the order of the serial loop). Every sum is therefore accumulated in the same order
whoever ran the tasks: the serial run, a local Dask cluster and any scheduler give bit-identical bins,
and at float64 the same bins as the serial loop always gave (``0 + x`` is exact). Any binned fit can
use it: the task's per-pair work is ``bin_block``'s (:func:`.model._block` for the dissimilarity, the
true distance from the positions), the runner is :func:`stridefix_analyzer.parallel.run_tasks`.

Scale: the full pair set of 100 000 scans is ~10⁹–5·10⁹ pairs; blocks are computed in
``dtype`` (float32 halves the memory traffic of the matrix products; RSS are whole dBm, so V, V² and
their products are integers, exact in float32 up to 2²⁴). When all pairs are too many, ``pair_fraction``
f < 1 fits on an **unbiased random subsample of scan pairs**: the scans of each group are put in a
random order (a fixed permutation from ``seed``) before blocking, and a uniformly random subset of the
block pairs (round(f·K) of the K, drawn uniformly without replacement) is binned. A block pair of permuted scans is a random set of scan pairs, and every pair lies in exactly one
block pair, so each pair is in the sample with the same probability: counts and sums are the full
set's in expectation (× the sampling fraction). The method text and the model JSON state the sample.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.parallel import run_tasks


@dataclasses.dataclass(frozen=True)
class BlockTask:
    """One block pair: rows i0.. against columns j0.. (j0 ≤ i0) of group ``group``'s scans."""

    group: int
    i0: int
    j0: int
    pairs: int  # unordered pairs the block pair holds


@dataclasses.dataclass
class GroupData:
    """A group's prepared fingerprints (``cm._Prepared``) and positions, in the blocking order."""

    prep: Any
    xy_m: np.ndarray


#: Block of the fit's pair blocks: 512 × 512 float32 temporaries (1 MB) stay in cache; measured on a
#: 20 000-scan fleet: 13 ns/pair at 512, 23 at 1024, 30 at 2048 (large blocks page-fault on every
#: temporary). bin_pairs keeps its own default (cm.DEFAULT_BLOCK).
FIT_BLOCK = 512


@dataclasses.dataclass
class BinSettings:
    mode: str = cm.DEFAULT_MODE
    width_db: float = cm.DEFAULT_BIN_WIDTH_DB
    block: int = FIT_BLOCK
    min_common: int = 1


def bin_block(task: BlockTask, shared: tuple[list[GroupData], BinSettings]) -> cm.PairBins:
    """The partial bins of one block pair (the loop body of the serial streaming fit)."""
    groups, s = shared
    g = groups[task.group]
    p, P = g.prep, g.xy_m
    n, i0, j0 = len(p), task.i0, task.j0
    ia, ib = slice(i0, min(n, i0 + s.block)), slice(j0, min(n, j0 + s.block))
    bins = cm.PairBins(width=s.width_db)
    D = cm._block(p, ia, p, ib, s.mode, s.min_common)
    keep = np.isfinite(D)
    bi, bj = D.shape
    tri = np.tri(bi, bj, -1, dtype=bool) if i0 == j0 else np.ones((bi, bj), bool)
    keep &= tri
    bins.n_no_common += int(np.sum(tri & ~keep))
    d2 = np.subtract.outer(P[ia, 0], P[ib, 0])
    d2 *= d2
    dy = np.subtract.outer(P[ia, 1], P[ib, 1])
    dy *= dy
    d2 += dy
    if i0 != j0 and keep.all():
        x, d2 = D.ravel(), d2.ravel()
    else:
        x, d2 = D[keep], d2[keep]
    bins.add(x, np.sqrt(d2), d2)
    return bins


def merge_bins(parts: list[cm.PairBins], into: cm.PairBins | None = None, width_db: float | None = None):
    """Sum of ``parts`` (in list order) added to ``into`` (default empty bins)."""
    out = into if into is not None else cm.PairBins(width=width_db or cm.DEFAULT_BIN_WIDTH_DB)
    for b in parts:
        if b.width != out.width:
            raise ValueError(f"bin widths differ: {b.width} vs {out.width}")
        n = len(b.count)
        if n > len(out.count):
            pad = n - len(out.count)
            out.count = np.concatenate([out.count, np.zeros(pad, np.int64)])
            out.sum_x, out.sum_d, out.sum_d2 = (
                np.concatenate([a, np.zeros(pad)]) for a in (out.sum_x, out.sum_d, out.sum_d2)
            )
        out.count[:n] += b.count
        out.sum_x[:n] += b.sum_x
        out.sum_d[:n] += b.sum_d
        out.sum_d2[:n] += b.sum_d2
        out.min_d = min(out.min_d, b.min_d)
        out.n_no_common += b.n_no_common
        out.n_pairs += b.n_pairs
    return out


def prepare_groups(
    R: np.ndarray,
    xy_m: np.ndarray,
    group: np.ndarray | None,
    dtype=np.float64,
    permute_seed: int | None = None,
) -> list[GroupData]:
    """Per group (sorted ids): its scans (only the APs it hears), optionally in a random order."""
    R = np.asarray(R, dtype=float)
    xy = np.asarray(xy_m, dtype=float)
    if xy.shape != (R.shape[0], 2):
        raise ValueError(f"xy_m shape {xy.shape} does not match {R.shape[0]} scans")
    group = np.zeros(len(R), np.int64) if group is None else np.asarray(group)
    rng = np.random.default_rng(permute_seed) if permute_seed is not None else None
    out = []
    for g in np.unique(group):
        sel = np.flatnonzero(group == g)
        if rng is not None:
            sel = sel[rng.permutation(len(sel))]
        Rg = R[sel]
        Rg = Rg[:, np.isfinite(Rg).any(axis=0)]
        out.append(GroupData(cm._Prepared(Rg, dtype=dtype), np.ascontiguousarray(xy[sel], dtype=dtype)))
    return out


def block_tasks(groups: list[GroupData], block: int) -> list[BlockTask]:
    """Every block pair (j0 ≤ i0) of every group, in the serial loop's order."""
    tasks = []
    for k, g in enumerate(groups):
        n = len(g.prep)
        for i0 in range(0, n, block):
            bi = min(n, i0 + block) - i0
            for j0 in range(0, i0 + 1, block):
                bj = min(n, j0 + block) - j0
                tasks.append(BlockTask(k, i0, j0, bi * (bi - 1) // 2 if i0 == j0 else bi * bj))
    return tasks


def sample_tasks(tasks: list[BlockTask], fraction: float, seed: int) -> list[BlockTask]:
    """round(f·K) of the block pairs, uniformly without replacement, kept in task order: every block
    pair is drawn with probability k/K, and every scan pair lies in exactly one, so every pair too."""
    if not 0 < fraction <= 1:
        raise ValueError(f"pair fraction {fraction} must be in (0, 1]")
    if fraction == 1 or not tasks:
        return tasks
    k = max(1, round(fraction * len(tasks)))
    rng = np.random.default_rng(seed + 1)
    pick = np.sort(rng.choice(len(tasks), size=k, replace=False))
    return [tasks[i] for i in pick]


def bin_pairs_tasks(
    R: np.ndarray,
    xy_m: np.ndarray,
    group: np.ndarray | None = None,
    settings: BinSettings | None = None,
    dtype=np.float64,
    scheduler: str | None = None,
    workers: int = 2,
    pair_fraction: float = 1.0,
    seed: int = 0,
    bins: cm.PairBins | None = None,
    client: Any = None,
) -> tuple[cm.PairBins, dict[str, Any]]:
    """Every (or a sampled ``pair_fraction`` of the) scan pairs of the same group into PairBins, the
    block pairs run by :func:`stridefix_analyzer.parallel.run_tasks`; returns (bins, info: tasks, pairs, sampling)."""
    settings = settings or BinSettings()
    sampled = pair_fraction < 1
    groups = prepare_groups(R, xy_m, group, dtype, permute_seed=seed if sampled else None)
    full = block_tasks(groups, settings.block)
    tasks = sample_tasks(full, pair_fraction, seed)
    parts = run_tasks(bin_block, tasks, scheduler, workers, shared=(groups, settings), client=client)
    out = merge_bins(parts, into=bins, width_db=settings.width_db)
    total = sum(t.pairs for t in full)
    info = {
        "block_pairs": len(tasks),
        "block_pairs_total": len(full),
        "pairs_total": int(total),
        "pairs_binned": int(sum(t.pairs for t in tasks)),
        "pair_fraction": pair_fraction,
        "dtype": np.dtype(dtype).name,
        "block": settings.block,
    }
    if sampled:
        info["sampling"] = (
            f"unbiased random subsample of scan pairs: {info['pairs_binned']} of {total} pairs "
            f"({len(tasks)} of {len(full)} blocks of {settings.block} randomly ordered scans, drawn "
            f"uniformly; seed {seed})"
        )
    return out, info


def bin_pairs(
    R: np.ndarray,
    xy_m: np.ndarray,
    group: np.ndarray | None = None,
    mode: str = cm.DEFAULT_MODE,
    width_db: float = cm.DEFAULT_BIN_WIDTH_DB,
    block: int = cm.DEFAULT_BLOCK,
    bins: cm.PairBins | None = None,
    min_common: int = 1,
) -> cm.PairBins:
    """Stream every unordered scan pair (i > j) of the same ``group`` (floor) into :class:`.model.PairBins`.

    Parameters
    ----------
    R : (n, m) RSS [dBm], NaN = not heard.
    xy_m : (n, 2) true positions [m].
    group : (n,) int, optional — pairs only within a group (e.g. the floor); default one group.

    Serial; :func:`bin_pairs_tasks` runs the same block pairs on Dask (bit-identical bins).
    """
    # the block pairs as tasks merged in the serial order, run here serially
    settings = BinSettings(mode=mode, width_db=width_db, block=block, min_common=min_common)
    out, _info = bin_pairs_tasks(R, xy_m, group, settings, bins=bins or cm.PairBins(width=width_db))
    return out
