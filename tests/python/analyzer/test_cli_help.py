"""What `stridefix ... --help` shows and the options the commands share.

GIVEN every parser of the `stridefix` tree (each sub-command and sub-sub-command), WHEN its help is
formatted, THEN it carries no docstring markup and no empty default; and an option several commands
take (--max-wifi-age-s, --jobs/--workers) has one default on all of them, the shared constant's.
"""

from __future__ import annotations

import argparse
import re

import pytest
from stridefix_analyzer import cli
from stridefix_analyzer.datasets.protocol import DEFAULT_MAX_WIFI_AGE_S
from stridefix_analyzer.helptext import plain
from stridefix_analyzer.parallel import DEFAULT_JOBS

MARKUP = re.compile(r"``|:(?:py:)?(?:func|mod|class|meth|data|attr|exc|obj|ref):`")
EMPTY_DEFAULT = re.compile(r"\(default: (?:None|False|\[\])\)")


def _parsers() -> list[tuple[str, argparse.ArgumentParser]]:
    out, seen = [], set()

    def walk(p: argparse.ArgumentParser, path: str) -> None:
        if id(p) in seen:
            return
        seen.add(id(p))
        out.append((path, p))
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, child in action.choices.items():
                    walk(child, f"{path} {name}")

    walk(cli.build_parser(), "stridefix")
    return out


PARSERS = _parsers()


def test_the_tree_has_every_sub_command():
    names = {path.split()[1] for path, _ in PARSERS if " " in path}
    assert names == set(cli.SUBCOMMANDS)
    assert len(PARSERS) >= 20  # bench, crowd, import, radiomap and realbench have their own


@pytest.mark.parametrize("path,parser", PARSERS, ids=[p for p, _ in PARSERS])
def test_help_has_no_markup_and_no_empty_default(path, parser):
    text = parser.format_help()
    assert MARKUP.findall(text) == [], path
    assert EMPTY_DEFAULT.findall(text) == [], path


def test_plain_removes_roles_and_literals():
    assert (
        plain("``stridefix bench``: see :func:`~a.b.run` and :mod:`.fusion`")
        == "stridefix bench: see run and fusion"
    )
    assert (
        plain(":data:`stridefix_analyzer.exits.HELP` and :class:`x.Y`")
        == "stridefix_analyzer.exits.HELP and x.Y"
    )


def _defaults(option: str) -> dict[str, object]:
    return {
        path: action.default
        for path, parser in PARSERS
        for action in parser._actions
        if option in action.option_strings
    }


def test_max_wifi_age_has_one_default():
    found = _defaults("--max-wifi-age-s")
    assert {"stridefix import msindoor", "stridefix import gsd", "stridefix realbench fusion"} <= set(found)
    assert "stridefix realbench pdr-distance" in found  # had 3 s while the importers had 2
    assert set(found.values()) == {DEFAULT_MAX_WIFI_AGE_S}


def test_jobs_has_one_default_and_one_spelling():
    found = {**_defaults("--jobs"), **_defaults("--workers")}
    assert len(found) >= 6  # realbench x3, crowd experiment and fit, radiomap build
    assert set(found.values()) == {DEFAULT_JOBS}
    for path, parser in PARSERS:
        for action in parser._actions:
            if "--jobs" in action.option_strings or "--workers" in action.option_strings:
                assert set(action.option_strings) == {"--jobs", "-j", "--workers"}, path


def test_global_quiet_and_verbose_come_before_the_sub_command():
    assert cli.split_global(["-q", "realbench", "--format", "gsd", "d", "-q"]) == (
        ["-q"],
        ["realbench", "--format", "gsd", "d", "-q"],
    )
    assert cli.split_global(["-v", "analyze", "x"]) == (["-v"], ["analyze", "x"])
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["-q", "-v", "analyze", "x"])  # one or the other


def test_version_prints_both_versions(capsys, monkeypatch, stridefixd):
    monkeypatch.setenv("STRIDEFIXD", str(stridefixd))
    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    first, second = capsys.readouterr().out.splitlines()
    assert re.fullmatch(r"stridefix \d+\.\d+\.\d+ \(analyzer\)", first)
    assert second.startswith("stridefixd ") and second.endswith(f" at {stridefixd}")


def test_version_says_where_stridefixd_was_looked_for(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("STRIDEFIXD", str(tmp_path / "nowhere"))
    with pytest.raises(SystemExit):
        cli.main(["--version"])
    assert f"stridefixd not found at {tmp_path / 'nowhere'}" in capsys.readouterr().out
