"""realbench crowd-map's per-fold crowd knowledge (realbench/crowdfolds.py): the heading variant the
training walks agree on, and its fleet priors, from their anchors only."""

from __future__ import annotations

import math

import numpy as np
import pytest
from stridefix_lab.realbench.crowdfolds import choose


def _sims(rng, spread_rad: dict[str, float], n: int = 12) -> list[dict]:
    return [
        {
            "walk": f"w{k}",
            "error": None,
            "sims": {v: (rng.normal(0.9, 0.05), rng.normal(1.5, s)) for v, s in spread_rad.items()},
        }
        for k in range(n)
    ]


def test_the_variant_walks_agree_on_is_chosen_with_its_priors():
    """GIVEN 12 walks whose heading bias spreads 40° under 'learned' and 5° under 'fixed'
    THEN 'fixed' is chosen and its priors centre on the walks' bias with a spread near 5°."""
    rng = np.random.default_rng(4)
    sims = _sims(rng, {"learned": math.radians(40), "fixed": math.radians(5)})
    variant, pri = choose(sims, ["learned", "fixed"])
    assert variant == "fixed"
    assert pri.walks_used == 12
    assert pri.heading_rad == pytest.approx(1.5, abs=0.1)
    assert math.radians(2) < pri.heading_sigma_rad < math.radians(12)
    assert pri.scale == pytest.approx(0.9, abs=0.05)


def test_variants_without_three_telling_walks_fall_back_to_the_first_uninformed():
    rng = np.random.default_rng(5)
    sims = _sims(rng, {"learned": 0.7, "fixed": 0.1}, n=2)
    sims.append({"walk": "w9", "error": None, "sims": {"learned": None, "fixed": None}})
    variant, pri = choose(sims, ["learned", "fixed"])
    assert variant == "learned" and pri.walks_used == 0 and pri.heading_sigma_rad == pytest.approx(math.pi)
