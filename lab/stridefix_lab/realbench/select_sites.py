"""The sites of the inner cross-validation (:mod:`.select`): a radio map of the group's total minus
the left-out blocks, with the floors, map rotation, heading candidate and stride K learned from the
remaining walks only, and the building content (walls, geo-reference, beacons: :mod:`.sitecontent`)
the fold sites carry, from those walks too: a choice is measured on what the folds will run.

:class:`SelectionSites` is the ``build_site`` callable :func:`.select.select` takes. Every inner-CV
row of :mod:`.tuning` uses the same block pairs, so each site is written once per group (``built``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.radiomap.build import WalkStats
from stridefix_analyzer.radiomap.heading import RotationSums, learn_heading
from stridefix_analyzer.radiomap.strides import stride_k

from stridefix_lab.realbench.floors import fold_floors
from stridefix_lab.realbench.fold import fold_site
from stridefix_lab.realbench.sitecontent import GroupContent, apply_fields


@dataclasses.dataclass
class SelectionSites:
    """Writes the selection sites of one group (see the module docstring)."""

    total: WalkStats
    walks: Sequence[Mapping[str, Any]]  # the group's prepared walks
    seg: Table  # their segments (:func:`stridefix_analyzer.radiomap.strides.build_segments`) and which are scored
    used: np.ndarray
    rotation: Sequence[Mapping[str, RotationSums]]
    heading_candidates: Mapping[str, Sequence[str]]
    min_count: int
    content: GroupContent | None = None
    built: dict[str, list[str]] = dataclasses.field(default_factory=dict)

    def __call__(self, removed: WalkStats, others: list[dict[str, Any]], name: str, path: Path) -> list[str]:
        """Write to ``path`` the site of ``total − removed`` learned from ``others``; returns the
        settings learned with it (heading candidate, stride K) for the replays on that site."""
        if str(path) in self.built:
            return self.built[str(path)]
        from stridefix_analyzer.io.sitefile import write_site

        idx = [j for j, w in enumerate(self.walks) if any(w is o for o in others)]
        heights, _, lowest = fold_floors(others, [])
        variant, _, rot = learn_heading([self.rotation[j] for j in idx])
        site, _ = fold_site(
            self.total,
            removed,
            name=name,
            rotation_deg=rot if math.isfinite(rot) else 0.0,
            floor_heights_m=heights,
            lowest_floor=lowest,
            min_count=self.min_count,
        )
        if self.content is not None:
            apply_fields(site, self.content.fold_fields(set(range(len(self.walks))) - set(idx))[0])
        write_site(path, site)
        k = stride_k(self.seg, self.used & np.isin(self.seg["walk"], idx))
        self.built[str(path)] = list(self.heading_candidates[variant]) + (
            [f"stride.weinberg_k={k:.6f}"] if math.isfinite(k) else []
        )
        return self.built[str(path)]
