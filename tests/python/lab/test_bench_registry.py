"""The lab's benches register themselves: a module of stridefix_lab.bench with a ``BENCH`` entry is a
bench of ``stridefix-lab bench`` (its own sub-command and options, ``--list``, ``all`` when it is a
``make bench`` one) with no CLI or Makefile edit."""

from __future__ import annotations

import argparse
import sys

import pytest
import stridefix_lab.bench as bench_pkg
from stridefix_lab.bench import cli as bench_cli
from stridefix_lab.bench.registry import Bench, benches

NEW_BENCH = """
from stridefix_lab.bench.registry import Bench


def _add(p):
    p.add_argument("--widgets", type=int, default=3)


def _run(args, firmware, seeds, out):
    print(f"widgets {args.widgets} seeds {seeds}")
    return [] if args.widgets < 5 else [f"widgets = {args.widgets} (target < 5)"]


BENCH = Bench("widgets", "counts widgets", _run, seeds="7", add_arguments=_add, needs_firmware=False)
"""


@pytest.fixture
def new_bench(tmp_path, monkeypatch):
    """A bench module dropped beside the others (a folder on the package's path)."""
    (tmp_path / "widgets_bench.py").write_text(NEW_BENCH)
    monkeypatch.setattr(bench_pkg, "__path__", [*bench_pkg.__path__, str(tmp_path)])
    yield
    sys.modules.pop("stridefix_lab.bench.widgets_bench", None)


def _parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    bench_cli.add_parser(parser.add_subparsers())
    return parser.parse_args(["bench", *argv])


def test_every_bench_module_is_found_with_its_help():
    found = benches()
    assert len(found) >= 12 and all(isinstance(b, Bench) and b.help for b in found.values())
    assert {"sil-pdr", "aadr2015", "real-targets", "reliability", "soak", "crowd-scale"} <= set(found)
    assert all(name == b.name for name, b in found.items())


def test_a_new_module_is_a_bench_with_its_own_options(new_bench, capsys, tmp_path):
    assert "widgets" in benches()
    assert bench_cli.run(_parse("--list")) == 0
    assert "widgets" in capsys.readouterr().out
    assert bench_cli.run(_parse("widgets", "--out", str(tmp_path))) == 0
    assert "widgets 3 seeds [7]" in capsys.readouterr().out
    assert bench_cli.run(_parse("widgets", "--widgets", "9", "--seeds", "1,2", "--out", str(tmp_path))) == 1
    out = capsys.readouterr().out
    assert "widgets 9 seeds [1, 2]" in out and "TARGET MISSED: widgets = 9" in out


def test_all_runs_only_the_make_bench_ones(monkeypatch, tmp_path, capsys):
    ran: list[str] = []

    def fake(name):
        return lambda args, fw, seeds, out: ran.append(name) or []

    found = {
        n: Bench(n, b.help, fake(n), b.seeds, b.add_arguments, False, b.in_make_bench)
        for n, b in benches().items()
    }
    monkeypatch.setattr(bench_cli, "benches", lambda: found)
    assert bench_cli.run(_parse("all", "--out", str(tmp_path))) == 0
    assert ran == [n for n, b in found.items() if b.in_make_bench] and "soak" not in ran and len(ran) >= 6


def test_no_bench_named_is_bad_usage(capsys):
    assert bench_cli.run(_parse()) == 2
    assert "--list" in capsys.readouterr().err
