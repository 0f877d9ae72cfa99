"""The site fields' physical ranges (``stridefix_common.site_ranges``: ``firmware/site_ranges.tsv``),
checked after every other field rule by :func:`stridefix_analyzer.io.sitefile.validate_site`;
``firmware/board/sf_site_ranges.c`` checks the same table in the same order with the same words.

A finite but absurd value (a map rotation of 3e38°, a reference point 3e38 m from the origin) passes
every finiteness rule and puts poses anywhere; the table gives each numeric field the range a building
can have. A refusal names the field and the element: ``"rp 2: rp_x_m = 3e+38 outside
-100000..100000 m"``. Cost O(total array length), numpy over each array.
"""

from __future__ import annotations

import numpy as np
from stridefix import site_t
from stridefix_common.site_ranges import SITE_RANGES, SiteRange

from stridefix_analyzer.io.site_v2 import SiteV2ValidationError


class SiteRangeError(SiteV2ValidationError):
    """A site field outside its range (sitefile re-raises it as SiteValidationError)."""


def _first_bad(values: np.ndarray, row: SiteRange) -> int:
    """Index of the first value outside the row's range (NaN too unless the row allows it), or −1."""
    with np.errstate(invalid="ignore"):
        bad = ~((values >= row.lo) & (values <= row.hi))
    if row.nan_ok:
        bad &= ~np.isnan(values)
    return int(np.argmax(bad)) if bad.any() else -1


def validate_ranges(site: site_t) -> None:
    """Every row of the table that applies (``when``) to ``site``; raise :class:`SiteRangeError` on the
    first value outside its range, naming the field and index. Array lengths were checked before."""
    for row in SITE_RANGES:
        if row.when is not None and not getattr(site, row.when):
            continue
        value = getattr(site, row.field)
        if row.count is None:
            i = _first_bad(np.asarray([value], float), row)
            if i >= 0:
                raise SiteRangeError(f"{row.field} = {value:g} outside {row.limits()}")
            continue
        i = _first_bad(np.asarray(value, float), row)
        if i < 0:
            continue
        v = value[i]
        if row.label is None:
            raise SiteRangeError(f"{row.field}[{i}] = {v:g} outside {row.limits()}")
        raise SiteRangeError(f"{row.label} {i}: {row.field} = {v:g} outside {row.limits()}")
