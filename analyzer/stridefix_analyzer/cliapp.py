"""A console script made of sub-commands: the machinery behind ``stridefix`` and ``stridefix-lab``.

Each sub-command lives in the module that does the work and contributes two functions:
``add_parser(subparsers)`` (declares its arguments and help) and ``run(args) -> int`` (the exit status).
A sub-command may also rewrite its own argument list before parsing (e.g. to supply a default
sub-sub-command): a :class:`CommandLine`'s ``argv_rewrites`` names that hook as ``"module:function"``,
``function(argv) -> argv``, applied only when that sub-command is the one given.
Exit status: the one contract of :mod:`stridefix_common.exits` (0 ok, 1 failed while running, 2 bad
usage or unreadable input, 3 nothing valid in the input), stated in every sub-command's ``--help``.
A sub-command checks its inputs itself (2 or 3, naming the file); an ``OSError`` that still escapes it
happened while it ran (an output that cannot be written, a read that failed midway): :meth:`main`
reports it in one line naming the file and exits 1, never with a traceback.
Global options, before the sub-command: ``-q``/``-v`` (:mod:`stridefix_analyzer.console`: what the
long-running commands print on stderr) and ``--version`` (the package's and the stridefixd's it runs).
Every ``--help`` goes through :mod:`stridefix_analyzer.helptext` (no docstring markup).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field

from stridefix_common.exits import EXIT_FAILURE, HELP

from stridefix_analyzer import __version__, console
from stridefix_analyzer.helptext import plain_parser

GLOBAL_QUIET = ("-q", "--quiet")
GLOBAL_VERBOSE = ("-v", "--verbose")


@dataclass
class CommandLine:
    """One console script: its name, its description and its sub-commands."""

    prog: str
    description: str
    #: sub-command name -> module providing add_parser() and run()
    subcommands: dict[str, str]
    #: sub-command name -> "module:function" rewriting argv before parsing
    argv_rewrites: dict[str, str] = field(default_factory=dict)

    def build_parser(self, only: str | None = None) -> argparse.ArgumentParser:
        """The parser with every sub-command, or with sub-command ``only`` alone.

        ``only`` is how :meth:`main` runs one sub-command: importing every sub-command's module
        (SciPy, Matplotlib, the crowd layers) costs 1-3 s on a 2-core machine, more than the
        analysis of a 1-hour walk, and the others' parsers are never used once the first word names
        a sub-command."""
        parser = argparse.ArgumentParser(prog=self.prog, description=self.description, epilog=HELP)
        talk = parser.add_mutually_exclusive_group()
        talk.add_argument(
            *GLOBAL_QUIET,
            dest="verbosity",
            action="store_const",
            const=console.QUIET,
            default=console.NORMAL,
            help="nothing on stderr but errors (no progress)",
        )
        talk.add_argument(
            *GLOBAL_VERBOSE,
            dest="verbosity",
            action="store_const",
            const=console.VERBOSE,
            help="a line per step of the long-running commands instead of one progress bar",
        )
        parser.add_argument(
            "--version",
            action=_VersionAction,
            help="the package's version and that of the stridefixd it runs (--stridefixd's default)",
        )
        sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
        for name, module_name in self.subcommands.items():
            if only is not None and name != only:
                continue
            try:
                module = importlib.import_module(module_name)
            except ImportError as exc:
                # One broken sub-command must not take the others down: it reports itself when used.
                p = sub.add_parser(name, help=f"(unavailable: {exc})")
                p.set_defaults(_run=_unavailable(f"{self.prog} {name}", exc))
                continue
            p = module.add_parser(sub)
            _add_exit_help(p)
            p.set_defaults(_run=module.run)
        plain_parser(parser)
        return parser

    def rewrite_argv(self, argv: list[str]) -> list[str]:
        """``argv`` after the rewrite hook of its sub-command (unchanged without one, or when the
        hook's module does not import: the sub-command then reports itself)."""
        ref = self.argv_rewrites.get(argv[0]) if argv else None
        if ref is None:
            return argv
        module_name, function = ref.split(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError:
            return argv
        return list(getattr(module, function)(argv))

    def main(self, argv: list[str] | None = None) -> int:
        front, rest = split_global(sys.argv[1:] if argv is None else list(argv))
        rest = self.rewrite_argv(rest)
        chosen = rest[0] if rest and rest[0] in self.subcommands else None  # else: help or a usage error
        args = self.build_parser(chosen).parse_args([*front, *rest])
        console.set_level(args.verbosity)
        try:
            return int(args._run(args) or 0)
        except OSError as exc:
            print(f"{self.prog} {args.command}: error: {os_error_text(exc)}", file=sys.stderr)
            return EXIT_FAILURE
        finally:
            console.end_progress()  # the command's live progress line, cleared whatever happened


def os_error_text(exc: OSError) -> str:
    """``exc`` as "FILE: what happened" (both files of a rename), without Python's ``[Errno N]``."""
    what = exc.strerror or str(exc)
    files = [os.fsdecode(f) for f in (exc.filename, exc.filename2) if f is not None]
    return f"{' -> '.join(files)}: {what}" if files else what


def split_global(argv: list[str]) -> tuple[list[str], list[str]]:
    """``argv`` as (the global -q/-v before the sub-command, the rest)."""
    n = 0
    while n < len(argv) and argv[n] in (*GLOBAL_QUIET, *GLOBAL_VERBOSE):
        n += 1
    return argv[:n], argv[n:]


def version_text() -> str:
    """``--version``: this package's version, then the stridefixd that commands run by default (its
    own ``--version`` line and path) or where it was looked for."""
    from stridefix_analyzer.firmware import Firmware

    fw = Firmware()
    if fw.path.is_file() and os.access(fw.path, os.X_OK):
        found = f"{fw.version()} at {fw.path}"
    else:
        found = f"stridefixd not found at {fw.path} (set $STRIDEFIXD, or put stridefixd on PATH)"
    return f"stridefix {__version__} (analyzer)\n{found}"


class _VersionAction(argparse.Action):
    def __init__(self, option_strings: list[str], dest: str, **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, help=kwargs.get("help"))  # type: ignore[arg-type]

    def __call__(self, parser: argparse.ArgumentParser, *_: object) -> None:
        print(version_text())
        parser.exit()


def _add_exit_help(parser: argparse.ArgumentParser) -> None:
    """The exit-status paragraph at the end of ``parser``'s help and of its sub-commands' (if any)."""
    parser.epilog = HELP if not parser.epilog else f"{parser.epilog}\n\n{HELP}"
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in set(action.choices.values()):
                _add_exit_help(child)


def _unavailable(prog: str, exc: ImportError) -> Callable[[argparse.Namespace], int]:
    def run(_args: argparse.Namespace) -> int:
        print(f"{prog}: unavailable: {exc}", file=sys.stderr)
        return EXIT_FAILURE

    return run
