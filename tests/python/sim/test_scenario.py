"""Scenario files: defaults, overrides, and clear errors (file and key named, exit status 2)."""

from __future__ import annotations

import json

import pytest
from stridefix_sim.scenario import (
    BUILTIN,
    DEFAULTS,
    ScenarioError,
    builtin_scenario,
    load_scenario,
    parse_scenario,
    resolve_scenario,
)


def test_file_overrides_only_its_keys(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(
        "seed = 5\n[walk]\nlaps = 1\n[[walk.pause]]\nat_m = 10\nduration_s = 2\n[can]\nloss_rate = 0.01\n"
    )
    sc = load_scenario(f)
    assert sc.seed == 5 and sc["walk"]["laps"] == 1.0 and sc["can"]["loss_rate"] == 0.01
    assert sc["walk"]["pause"] == [{"at_m": 10.0, "duration_s": 2.0}]
    assert sc["walk"]["cadence_hz"] == DEFAULTS["walk"]["cadence_hz"]
    assert sc.source == str(f)


@pytest.mark.parametrize(
    "text, key",
    [
        ("colour = 1\n", "colour"),
        ("[walk]\nlapz = 2\n", "walk.lapz"),
        ("[imu.extra]\nx = 1\n", "imu.extra"),
        ("[[walk.pause]]\nat_m = 3\nduration_s = 1\nwhy = 'coffee'\n", "walk.pause[0].why"),
    ],
)
def test_unknown_key_is_an_error_naming_file_and_key(tmp_path, text, key):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    with pytest.raises(ScenarioError) as e:
        load_scenario(f)
    assert str(f) in str(e.value) and f"'{key}'" in str(e.value)


@pytest.mark.parametrize(
    "text, key",
    [
        ("[walk]\nlaps = 'two'\n", "walk.laps"),
        ("[can]\nloss_rate = 1.5\n", "can.loss_rate"),
        ("[can]\nboard_time_start_ms = 4294967296\n", "can.board_time_start_ms"),
        ("[imu]\ngyro_bias_dps = [1, 2]\n", "imu.gyro_bias_dps"),
        ("[world]\nname = 'mars'\n", "world.name"),
        ("[walk]\npace = 'jog'\n", "walk.pace"),
        ("[walk]\nroute = 'roof'\n", "walk.route"),
        ("[walk]\nsurge = 0.1\n", "walk.surge"),
        ("[person]\nweinberg_k = 2.0\n", "person.weinberg_k"),
    ],
)
def test_bad_values_are_errors_naming_the_key(text, key):
    with pytest.raises(ScenarioError, match=f"x.toml: .*'{key}'"):
        parse_scenario(text, source="x.toml")


def test_cli_unknown_key_exits_2_with_message(tmp_path, sim_cli, capsys):
    f = tmp_path / "bad.toml"
    f.write_text("[walk]\nlapz = 2\n")
    assert sim_cli(["--scenario", str(f), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert str(f) in err and "walk.lapz" in err
    assert not (tmp_path / "o").exists()


def test_cli_missing_file_and_bad_toml_exit_2(tmp_path, sim_cli, capsys):
    missing = tmp_path / "nope.toml"
    assert sim_cli(["--scenario", str(missing), "--out", str(tmp_path / "o")]) == 2
    assert str(missing) in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text("[walk\nlaps = 2\n")
    assert sim_cli(["--scenario", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and "TOML" in err


def test_cli_bad_override_exits_2(tmp_path, sim_cli, capsys):
    assert sim_cli(["--loss-rate", "2", "--out", str(tmp_path / "o")]) == 2
    assert "can.loss_rate" in capsys.readouterr().err


def test_builtin_named_scenarios():
    assert set(BUILTIN) == {
        "default",
        "pace_slow",
        "pace_normal",
        "pace_fast",
        "office_survey",
        "aadr2015_slow",
        "aadr2015",
        "aadr2015_fast",
        "aadr2015_survey",
        "campus",
        "campus_survey",
        "campus2",
        "campus2_survey",
    }
    assert builtin_scenario("campus")["world"]["name"] == "campus"
    assert builtin_scenario("campus2")["walk"]["route"] == "legs"
    assert builtin_scenario("campus2_survey")["survey"]["layout"] == "world"
    assert builtin_scenario("campus")["walk"]["route"] == "track"
    assert builtin_scenario("campus_survey")["survey"]["enabled"]
    assert resolve_scenario(None).data == resolve_scenario("default").data == DEFAULTS
    assert DEFAULTS["walk"]["route"] == "tour" and DEFAULTS["walk"]["pace"] == "normal"
    for pace in ("slow", "normal", "fast"):
        sc = builtin_scenario(f"pace_{pace}")
        assert sc["walk"]["pace"] == pace and sc["walk"]["route"] == "loop" and sc["walk"]["laps"] == 2.0
        assert sc.source == f"<built-in pace_{pace}>"


def test_cli_named_scenario_and_unknown_name(tmp_path, sim_cli, capsys):
    assert sim_cli(["--scenario", "pace_fast", "--duration-s", "5", "--out", str(tmp_path / "o")]) == 0
    summary = json.loads((tmp_path / "o" / "sim_summary.json").read_text())
    assert summary["pace"] == "fast" and summary["scenario_source"] == "<built-in pace_fast>"
    assert sim_cli(["--scenario", "pace_jog", "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert "pace_jog" in err and "pace_slow" in err
