"""The errors of reading a result file (:mod:`.results`): every one names the file, and a file that is
not JSON at all is "nothing valid in the input" for the exit status."""

from __future__ import annotations

from stridefix_common.exits import NothingValid


class ResultsFileError(ValueError):
    """A result file is missing, not JSON, of another kind or lacks a key; the message names it."""


class NotAResultsFileError(ResultsFileError, NothingValid):
    """A result file was read but is not JSON (empty, binary, UTF-16, a 5000-digit number): nothing
    valid in it (exit :data:`~stridefix_common.exits.EXIT_NOTHING_VALID`). JSON of another shape or
    kind is a :class:`ResultsFileError` (2), as a config of unknown keys is."""
