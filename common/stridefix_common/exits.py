"""The exit-status contract of every ``stridefix`` command, the same as ``stridefixd``'s.

The C side is ``SF_EXIT_*`` in firmware/app/sf_options.h; tests/python/analyzer/test_exits.py keeps the
two equal. docs/reliability.md has the table. A command over several inputs exits with the worst
status of its inputs (:func:`worst`): a failure before an unreadable input before one with nothing valid.
"""

from __future__ import annotations

from collections.abc import Iterable

#: the input was read and held valid records (bad ones are counted and skipped)
EXIT_OK = 0
#: a failure while running: an output could not be written, the work failed
EXIT_FAILURE = 1
#: bad usage, or an input that cannot be read (missing, a directory or device where a file is expected)
EXIT_USAGE = 2
#: the input was read but held not one valid record (an empty file, binary junk, a header only)
EXIT_NOTHING_VALID = 3

#: the contract in one paragraph, for ``--help``
HELP = (
    f"Exit status (the same for stridefixd): {EXIT_OK} the input was read and held valid records "
    f"(bad ones are counted and skipped); {EXIT_FAILURE} a failure while running (e.g. an output "
    f"could not be written); {EXIT_USAGE} bad usage, or an input that cannot be read (missing, a "
    f"directory or a device where a file is expected); {EXIT_NOTHING_VALID} nothing valid in the "
    "input (empty, binary junk, a header only). With several inputs: the worst of theirs."
)

_SEVERITY = (EXIT_OK, EXIT_NOTHING_VALID, EXIT_USAGE, EXIT_FAILURE)


class NothingValid(Exception):
    """Mixin of the input errors that mean "read, but not one valid record in it" (a file that is not
    an LCM log, a trace without a sensor record): :func:`input_error_status` maps them to
    :data:`EXIT_NOTHING_VALID`, every other input error to :data:`EXIT_USAGE`."""


def input_error_status(exc: BaseException) -> int:
    """The exit status of a command stopped by the input error ``exc``."""
    return EXIT_NOTHING_VALID if isinstance(exc, NothingValid) else EXIT_USAGE


def worst(statuses: Iterable[int]) -> int:
    """The most serious of ``statuses`` (failure > unreadable or usage > nothing valid > ok); 0 for none."""
    return max(statuses, key=_SEVERITY.index, default=EXIT_OK)
