"""The exit-status contract: one table for stridefixd and every `stridefix` command.

The codes are defined once per language, SF_EXIT_* in firmware/app/sf_options.h and
stridefix_analyzer/exits.py; this test keeps them equal, and checks that both `--help` texts state
them."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from stridefix_analyzer import cli
from stridefix_common import exits

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


# --- the same pattern in the other commands --------------------------------------------------------


def test_analyze_of_junk_or_empty_logs_is_nothing_valid(write_log, tmp_path, cli_main, capsys):
    """Regression: a PNG given as a log exited 2 like a missing file; two logs without one
    event exited 2 as if one channel were missing. Both hold nothing valid: 3."""
    png = tmp_path / "photo.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4)
    assert cli_main(["analyze", str(png), "--out", str(tmp_path / "o")]) == exits.EXIT_NOTHING_VALID
    assert "nothing valid in the input: not an LCM event log" in capsys.readouterr().err
    empty = write_log("empty.lcmlog", [])
    assert cli_main(["analyze", str(empty), "--out", str(tmp_path / "o")]) == exits.EXIT_NOTHING_VALID
    assert cli_main(["radiomap", "build", str(png), "--out", str(tmp_path / "s.sfsite")]) == (
        exits.EXIT_NOTHING_VALID
    )


@pytest.mark.parametrize("path", ["/dev/zero", "/tmp"])
def test_site_file_that_is_not_a_file_is_refused(path, cli_main, capsys):
    assert cli_main(["radiomap", "show", path]) == exits.EXIT_USAGE
    assert "not a regular file" in capsys.readouterr().err


@pytest.mark.parametrize("value", ["nan", "inf", "-1", "x"])
def test_import_seconds_are_parsed_strictly(value, tmp_path, cli_main):
    with pytest.raises(SystemExit) as exc:
        cli_main(["import", "gsd", "x.txt", "-o", str(tmp_path / "x"), "--max-wifi-age-s", value])
    assert exc.value.code == exits.EXIT_USAGE
