"""The benches, found without a list: every module of :mod:`stridefix_lab.bench` that defines
``BENCH`` (a :class:`Bench`) is one, so adding a bench is its module and its test, no CLI or
Makefile edit (``stridefix-lab bench NAME``; ``make bench`` runs those with ``in_make_bench``).

A bench's ``run(args, firmware, seeds, out)`` runs it, writes its JSON under ``out``, prints its
table and returns one line per target it missed (``TARGET MISSED: ...`` on stdout, exit 1).
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from stridefix_analyzer.firmware import Firmware

Runner = Callable[[argparse.Namespace, Firmware, list[int], Path], list[str]]


class BenchUsageError(ValueError):
    """A bench option holds a value the bench does not know (exit 2)."""


@dataclass(frozen=True)
class Bench:
    """One bench: its name on the command line, a line of help, and how it runs."""

    name: str
    help: str
    run: Runner
    #: the seeds it runs by default (``--seeds``)
    seeds: str = "1"
    #: declares the bench's own options (beside --seeds, --stridefixd, --out and --set)
    add_arguments: Callable[[argparse.ArgumentParser], None] | None = None
    #: False: it runs no firmware (no --stridefixd needed)
    needs_firmware: bool = True
    #: ``make bench`` (``stridefix-lab bench all``) runs it
    in_make_bench: bool = False


def benches() -> dict[str, Bench]:
    """Every bench by name, in name order."""
    found: dict[str, Bench] = {}
    package = importlib.import_module("stridefix_lab.bench")
    for info in pkgutil.iter_modules(package.__path__):
        bench = getattr(importlib.import_module(f"stridefix_lab.bench.{info.name}"), "BENCH", None)
        if isinstance(bench, Bench):
            if bench.name in found:
                raise ValueError(f"two benches named {bench.name!r}")
            found[bench.name] = bench
    return dict(sorted(found.items()))
