"""The errors of reading a result file (:mod:`.results`): every one names the file, and a file that is
not a JSON object at all is "nothing valid in the input" for the exit status."""

from __future__ import annotations

from stridefix_common.exits import NothingValid


class ResultsFileError(ValueError):
    """A result file is missing, not JSON, of another kind or lacks a key; the message names it."""


class NotAResultsFileError(ResultsFileError, NothingValid):
    """A result file was read but is not a JSON object (empty, binary, UTF-16, not JSON): nothing
    valid in it (exit :data:`~stridefix_common.exits.EXIT_NOTHING_VALID`)."""
