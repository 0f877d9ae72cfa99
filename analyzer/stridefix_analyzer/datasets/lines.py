"""The text-file side of the importers (msindoor traces, GetSensorData logs): open the file, hand out
its non-blank lines with their numbers, and keep the books on lines that are skipped.

A malformed line is never fatal: :meth:`LineReader.bad` records (line number, reason) and warns with a
:class:`MalformedLineWarning` naming ``file:line``, one by one up to ``max_line_warnings``; after the
loop, :meth:`LineReader.finish` sums the rest up in one warning. Lines of a known but unused record
type are counted per type (:meth:`LineReader.ignore`), not reported.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator

#: bytes of a file's head looked at by :func:`not_text_hint`
SNIFF_BYTES = 4096
_BOMS = {b"\xff\xfe": "UTF-16 (little-endian)", b"\xfe\xff": "UTF-16 (big-endian)"}


def not_text_hint(path: str | os.PathLike[str]) -> str | None:
    """Why a file that gave no valid line is probably not UTF-8 text: a UTF-16 byte-order mark, NUL
    bytes (binary data) or no byte at all; None when its head looks like text (or cannot be read)."""
    try:
        with open(path, "rb") as f:
            head = f.read(SNIFF_BYTES)
    except OSError:
        return None
    if not head:
        return "the file is empty"
    for bom, name in _BOMS.items():
        if head.startswith(bom):
            return f"it starts with a {name} byte-order mark: convert it to UTF-8"
    nul = head.find(b"\0")
    if nul >= 0:
        return f"it holds NUL bytes (the first at byte {nul}): binary data, not a text log"
    return None


class MalformedLineWarning(UserWarning):
    """A line of a trace was skipped; the message names the file and line."""


class LineReader:
    """Reads ``path`` line by line for one importer; ``error`` is the importer's read error class,
    built as ``error(path, reason)`` (missing file, not a file, unreadable)."""

    def __init__(self, path: str | os.PathLike[str], error: type[Exception], max_line_warnings: int):
        self.path = os.fspath(path)
        self.error = error
        self.max_line_warnings = max_line_warnings
        self.skipped: list[tuple[int, str]] = []
        self.ignored: dict[str, int] = {}
        self.n_lines = 0
        if not os.path.exists(self.path):
            raise error(self.path, "no such file")
        if not os.path.isfile(self.path):
            raise error(self.path, "not a regular file")

    def lines(self) -> Iterator[tuple[int, str]]:
        """(line number from 1, the line without its end of line) of every non-blank line."""
        try:
            with open(self.path, "r", encoding="utf-8", errors="replace", newline="") as f:
                for line_no, line in enumerate(f, 1):
                    self.n_lines += 1
                    line = line.rstrip("\r\n")
                    # = line.strip() != "" without building the stripped copy
                    if line and not line.isspace():
                        yield line_no, line
        except OSError as exc:
            raise self.error(self.path, f"cannot read ({exc.strerror or exc})") from exc

    def bad(self, line_no: int, reason: str) -> None:
        """Skip a malformed line (stacklevel: the warning points at the importer's caller)."""
        self.skipped.append((line_no, reason))
        if len(self.skipped) <= self.max_line_warnings:
            warnings.warn(
                f"{self.path}:{line_no}: skipped malformed line ({reason})",
                MalformedLineWarning,
                stacklevel=3,
            )

    def ignore(self, kind: str) -> None:
        """Count a line of a known record type the importer does not use."""
        self.ignored[kind] = self.ignored.get(kind, 0) + 1

    def finish(self) -> None:
        """After the loop: one warning for the malformed lines beyond ``max_line_warnings``."""
        if len(self.skipped) > self.max_line_warnings:
            warnings.warn(
                f"{self.path}: {len(self.skipped) - self.max_line_warnings} more malformed "
                f"line(s) skipped ({len(self.skipped)} in all)",
                MalformedLineWarning,
                stacklevel=3,
            )
