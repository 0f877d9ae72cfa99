"""The top-level CLI: sub-commands by registry, argv rewrite hooks applied only to their sub-command."""

from __future__ import annotations

import subprocess
import sys

from stridefix_analyzer import cli
from stridefix_lab import cli as lab_cli


def test_every_rewrite_hook_belongs_to_a_registered_sub_command():
    for app in (cli, lab_cli):
        assert set(app.ARGV_REWRITES) <= set(app.SUBCOMMANDS)
        assert all(ref.count(":") == 1 for ref in app.ARGV_REWRITES.values())


def test_realbench_format_runs_the_fusion_bench_through_the_hook():
    # `stridefix-lab realbench --format gsd DIR` means `stridefix-lab realbench fusion --format gsd DIR`
    assert lab_cli.rewrite_argv(["realbench", "--format", "gsd", "d"])[:2] == ["realbench", "fusion"]
    assert lab_cli.rewrite_argv(["realbench", "pdr-distance", "--floor", "x"])[1] == "pdr-distance"


def test_other_sub_commands_pass_unchanged(monkeypatch):
    monkeypatch.setitem(cli.ARGV_REWRITES, "analyze", "no_such_module_anywhere:f")
    assert cli.rewrite_argv(["analyze", "x"]) == ["analyze", "x"]  # a hook that cannot load is skipped
    assert cli.rewrite_argv(["report", "d"]) == ["report", "d"]
    assert cli.rewrite_argv([]) == []


def test_running_one_sub_command_builds_only_its_parser():
    # stridefix analyze of a 1-hour walk spent 1-3 s importing every sub-command's module (SciPy,
    # Matplotlib, the crowd and bench layers) before reading a byte; the cost budget holds the whole run
    # at 3 s. A fresh interpreter, so that modules other tests imported do not count.
    script = (
        "import sys\n"
        "from stridefix_analyzer import cli\n"
        "p = cli.build_parser('analyze')\n"
        "sub = next(a for a in p._actions if a.dest == 'command')\n"
        "print(sorted(sub.choices), sorted({m.split('.')[0] for m in sys.modules} & {'scipy', 'matplotlib'}))\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert out.split("\n")[0] == "['analyze'] []"
    every = next(a for a in cli.build_parser()._actions if a.dest == "command")
    assert sorted(every.choices) == sorted(cli.SUBCOMMANDS)  # top-level help lists them all
