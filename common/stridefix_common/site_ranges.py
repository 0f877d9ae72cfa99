"""The physical range of every numeric site field: ``site_ranges.tsv``, the one table both site readers
check (the firmware's ``firmware/board/sf_site_ranges.c`` through a header generated from it, the
analyzer's ``stridefix_analyzer.io.site_ranges``).

The file lives at ``firmware/site_ranges.tsv`` (its header says what each column means);
``stridefix_common/site_ranges.tsv`` is a link to it in a checkout and a copy of it in a wheel, as
``board.dbc`` is.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

#: the table as a file (packages are installed as folders, never zipped)
SITE_RANGES_PATH = Path(str(resources.files(__package__ or "stridefix_common") / "site_ranges.tsv"))
COLUMNS = ("field", "count", "label", "when", "min", "max", "unit", "nan")


@dataclass(frozen=True)
class SiteRange:
    """One row: ``field`` must be within ``lo`` … ``hi`` (see site_ranges.tsv)."""

    field: str
    #: None: a scalar; a str: the n_* count of the array; an int: a fixed-size array's length
    count: str | int | None
    #: what an element is called in a refusal, or None for ``field[i]``
    label: str | None
    #: the field that must be true / non-zero for the row to apply, or None: always
    when: str | None
    lo: float
    hi: float
    unit: str
    nan_ok: bool

    def limits(self) -> str:
        """``"<min>..<max>[ <unit>]"``, as both readers print it (``%g`` / ``:g``)."""
        return f"{self.lo:g}..{self.hi:g}" + (f" {self.unit}" if self.unit else "")


def _cell(text: str) -> str | None:
    return None if text == "-" else text


def parse(text: str, source: str = "site_ranges.tsv") -> tuple[SiteRange, ...]:
    """The rows of a site-ranges table; raises ValueError naming the line when one is malformed."""
    rows: list[SiteRange] = []
    header = True
    for no, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        cells = line.split("\t")
        if header:
            if tuple(cells) != COLUMNS:
                raise ValueError(f"{source}:{no}: header {cells}, expected {list(COLUMNS)}")
            header = False
            continue
        if len(cells) != len(COLUMNS):
            raise ValueError(f"{source}:{no}: {len(cells)} columns, expected {len(COLUMNS)}")
        field, count, label, when, lo, hi, unit, nan = cells
        c = _cell(count)
        rows.append(
            SiteRange(
                field=field,
                count=int(c) if c is not None and c.isdigit() else c,
                label=_cell(label),
                when=_cell(when),
                lo=float(lo),
                hi=float(hi),
                unit=_cell(unit) or "",
                nan_ok=nan == "nan",
            )
        )
    return tuple(rows)


#: every row of the table, in its order (the order both readers check them in)
SITE_RANGES: tuple[SiteRange, ...] = parse(
    SITE_RANGES_PATH.read_text(encoding="utf-8"), str(SITE_RANGES_PATH)
)
