"""stridefixd --print-config: the INI text reads back as a config, and --json exports the parameter
table and the schemes for tools (the analyzer reads keys and defaults from it instead of re-typing them).

GIVEN the built firmware, WHEN its configuration is printed, THEN (INI) `--config` accepts the printout
and the effective values equal the printed ones, and (JSON) the document parses, lists every key of
the INI printout once with its default, range, unit and help, and lists the schemes of
pose_t.SCHEME_* by id and name."""

from __future__ import annotations

import configparser
import json
import subprocess
from pathlib import Path

import pytest
from stridefix import pose_t


def _run(stridefixd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(stridefixd), *args], capture_output=True, text=True, timeout=60)


def _ini_values(text: str) -> dict[str, str]:
    cp = configparser.ConfigParser(comment_prefixes=("#",), interpolation=None)
    cp.read_string(text)
    return {f"{s}.{k}": v for s in cp.sections() for k, v in cp[s].items()}


def test_print_config_round_trips_through_config(stridefixd, default_walk, tmp_path):
    """Regression: two comment lines were longer than inih's 200-character line limit, so
    `--print-config > all.ini; --config all.ini` failed on a split line."""
    printed = _run(stridefixd, "--print-config")
    assert printed.returncode == 0, printed.stderr
    assert max(len(line) for line in printed.stdout.splitlines()) < 199
    all_ini = tmp_path / "all.ini"
    all_ini.write_text(printed.stdout)
    again = _run(stridefixd, "--config", str(all_ini), "--print-config")
    assert again.returncode == 0, again.stderr
    assert again.stdout == printed.stdout
    # a walk, not /dev/null: a device is refused as input, and an empty input exits "nothing valid"
    walk = default_walk["dir"] / "board.candump"
    run = _run(stridefixd, "--config", str(all_ini), "--input", str(walk), "--no-log", "-q")
    assert run.returncode == 0, run.stderr


def test_round_trip_keeps_a_changed_value(stridefixd, tmp_path):
    printed = _run(stridefixd, "--print-config", "--set", "stride.weinberg_k=0.55").stdout
    ini = tmp_path / "k.ini"
    ini.write_text(printed)
    assert (
        _ini_values(_run(stridefixd, "--config", str(ini), "--print-config").stdout)["stride.weinberg_k"]
        == "0.55"
    )


@pytest.fixture(scope="module")
def config_json(stridefixd) -> dict:
    proc = _run(stridefixd, "--print-config", "--json")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_json_lists_every_key_of_the_ini(stridefixd, config_json):
    ini = _ini_values(_run(stridefixd, "--print-config").stdout)
    keys = [p["key"] for p in config_json["params"]]
    assert len(keys) == len(set(keys))
    assert set(keys) == set(ini)
    for p in config_json["params"]:
        assert set(p) >= {"key", "section", "name", "type", "default", "value", "min", "max", "unit", "help"}
        assert p["key"] == f"{p['section']}.{p['name']}"
        assert p["type"] in ("double", "int32")
        assert p["min"] <= p["default"] <= p["max"], p["key"]
        assert float(ini[p["key"]]) == pytest.approx(p["value"], rel=1e-8, abs=1e-12)
        want = int if p["type"] == "int32" else float
        assert all(isinstance(p[f], want) for f in ("default", "value", "min", "max")), p["key"]


def test_json_value_follows_set_and_default_does_not(stridefixd):
    doc = json.loads(_run(stridefixd, "--print-config", "--json", "--set", "fusion.static_alpha=0.25").stdout)
    row = next(p for p in doc["params"] if p["key"] == "fusion.static_alpha")
    assert (row["default"], row["value"]) == (0.5, 0.25)


def test_json_schemes_are_pose_t_constants(config_json):
    want = {
        name[len("SCHEME_") :].lower(): getattr(pose_t, name)
        for name in dir(pose_t)
        if name.startswith("SCHEME_")
    }
    got = {s["name"]: s["id"] for s in config_json["schemes"]}
    assert got == want
    scheme_row = next(p for p in config_json["params"] if p["key"] == "output.scheme")
    assert scheme_row["max"] == max(want.values())


def test_json_needs_print_config(stridefixd):
    proc = _run(stridefixd, "--json", "--input", "/dev/null")
    assert proc.returncode == 2
    assert "--print-config" in proc.stderr
