"""The exit-status contract (issue 12): one table for stridefixd and every `stridefix` command.

The codes are defined once per language, SF_EXIT_* in firmware/app/sf_options.h and
stridefix_analyzer/exits.py; this test keeps them equal, and checks that both `--help` texts state
them."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from stridefix_analyzer import cli, exits

REPO = Path(__file__).resolve().parents[3]
PAIRS = {
    "SF_EXIT_OK": "EXIT_OK",
    "SF_EXIT_FAILURE": "EXIT_FAILURE",
    "SF_EXIT_USAGE": "EXIT_USAGE",
    "SF_EXIT_NOTHING_VALID": "EXIT_NOTHING_VALID",
}


def _c_codes() -> dict[str, int]:
    text = (REPO / "firmware" / "app" / "sf_options.h").read_text(encoding="utf-8")
    return {m[1]: int(m[2]) for m in re.finditer(r"^#define (SF_EXIT_\w+) (\d+)", text, flags=re.M)}


def test_c_and_python_codes_agree():
    assert set(_c_codes()) == set(PAIRS)
    for c_name, py_name in PAIRS.items():
        assert _c_codes()[c_name] == getattr(exits, py_name), c_name
    assert len(set(_c_codes().values())) == len(PAIRS)


def test_stridefixd_help_states_every_code(stridefixd):
    text = subprocess.run([str(stridefixd), "--help"], capture_output=True, text=True, timeout=30).stdout
    block = text[text.index("Exit status") :]
    for code in _c_codes().values():
        assert re.search(rf"^\s+{code}  \S", block, flags=re.M), code


@pytest.mark.parametrize("argv", [[], ["import", "gsd"], ["analyze"], ["radiomap", "build"], ["sim"]])
def test_every_stridefix_help_states_the_contract(argv, capsys):
    with pytest.raises(SystemExit):
        cli.main([*argv, "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert exits.HELP in out


def test_worst_status_of_several_inputs():
    assert exits.worst([]) == exits.EXIT_OK
    assert exits.worst([0, 3, 0]) == exits.EXIT_NOTHING_VALID
    assert exits.worst([3, 2, 0]) == exits.EXIT_USAGE
    assert exits.worst([2, 1, 3]) == exits.EXIT_FAILURE
