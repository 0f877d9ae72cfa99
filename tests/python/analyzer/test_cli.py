"""The top-level CLI: sub-commands by registry, argv rewrite hooks applied only to their sub-command."""

from __future__ import annotations

from stridefix_analyzer import cli


def test_every_rewrite_hook_belongs_to_a_registered_sub_command():
    assert set(cli.ARGV_REWRITES) <= set(cli.SUBCOMMANDS)
    assert all(ref.count(":") == 1 for ref in cli.ARGV_REWRITES.values())


def test_realbench_format_runs_the_fusion_bench_through_the_hook():
    # `stridefix realbench --format gsd DIR` means `stridefix realbench fusion --format gsd DIR`
    assert cli.rewrite_argv(["realbench", "--format", "gsd", "d"])[:2] == ["realbench", "fusion"]
    assert cli.rewrite_argv(["realbench", "pdr-distance", "--floor", "x"])[1] == "pdr-distance"


def test_other_sub_commands_pass_unchanged(monkeypatch):
    monkeypatch.setitem(cli.ARGV_REWRITES, "analyze", "no_such_module_anywhere:f")
    assert cli.rewrite_argv(["analyze", "x"]) == ["analyze", "x"]  # a hook that cannot load is skipped
    assert cli.rewrite_argv(["report", "d"]) == ["report", "d"]
    assert cli.rewrite_argv([]) == []
