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


def _numeric_keys(table: dict, prefix: str = "") -> list[tuple[str, object]]:
    """(dotted key, default) of every numeric key of ``table``: numbers, lists of numbers (an empty
    default list is a list of times), and the pauses' at_m and duration_s."""
    out: list[tuple[str, object]] = []
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out += _numeric_keys(value, f"{name}.")
        elif key == "pause":
            out += [(f"{name}[0].at_m", 10.0), (f"{name}[0].duration_s", 2.0)]
        elif isinstance(value, list) or (isinstance(value, (int, float)) and not isinstance(value, bool)):
            out.append((name, value))
    return out


def _toml_with(key: str, bad: str) -> str:
    """A scenario file that sets ``key`` (dotted) to the TOML float ``bad`` (nan, inf, -inf); in a list,
    its first element."""
    if key.startswith("walk.pause[0]."):
        leaf = key.rsplit(".", 1)[1]
        other = {"at_m": "duration_s = 2.0", "duration_s": "at_m = 10.0"}[leaf]
        return f"[[walk.pause]]\n{leaf} = {bad}\n{other}\n"
    *tables, leaf = key.split(".")
    default = DEFAULTS
    for t in tables:
        default = default[t]
    value = default[leaf]
    if isinstance(value, list):
        rest = [repr(float(v)) for v in value[1:]]
        text = f"{leaf} = [{', '.join([bad, *rest])}]"
    else:
        text = f"{leaf} = {bad}"
    return (f"[{'.'.join(tables)}]\n" if tables else "") + text + "\n"


_NUMERIC_KEYS = _numeric_keys(DEFAULTS)


def test_every_numeric_key_is_listed():
    keys = {k for k, _ in _NUMERIC_KEYS}
    assert {"seed", "duration_s", "mounting.roll_deg", "imu.accel_bias_mps2", "walk.pause[0].at_m"} <= keys
    assert "faults.silence_at_s" in keys and "gnss.tau_s" in keys and len(keys) > 90


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
@pytest.mark.parametrize("key", [k for k, _ in _NUMERIC_KEYS])
def test_non_finite_values_are_errors_naming_the_key(key, bad):
    text = _toml_with(key, bad)
    with pytest.raises(ScenarioError) as e:
        parse_scenario(text, source="x.toml")
    assert str(e.value).startswith("x.toml: ") and f"'{key}'" in str(e.value), (text, str(e.value))


@pytest.mark.parametrize(
    "overrides, key",
    [
        ({"seed": -1}, "seed"),
        ({"duration_s": float("inf")}, "duration_s"),
        ({"duration_s": float("nan")}, "duration_s"),
        ({"duration_s": 1e12}, "duration_s"),
        ({"mounting.roll_deg": float("nan")}, "mounting.roll_deg"),
        ({"world.map_rotation_deg": 3e38}, "world.map_rotation_deg"),
        ({"imu.accel_noise_mps2": -0.1}, "imu.accel_noise_mps2"),
        ({"baro.sea_level_pa": 0.0}, "baro.sea_level_pa"),
        ({"radio.path_loss_exponent": 0.0}, "radio.path_loss_exponent"),
        ({"mag.dip_deg": 95.0}, "mag.dip_deg"),
        ({"walk.laps": 1e9}, "walk.laps"),
    ],
)
def test_out_of_range_overrides_are_errors_naming_the_key(overrides, key):
    with pytest.raises(ScenarioError) as e:
        resolve_scenario("default").with_overrides(**overrides)
    assert f"'{key}'" in str(e.value)


@pytest.mark.parametrize(
    "text, key",
    [
        ("duration_s = inf\n", "duration_s"),
        ("seed = -1\n", "seed"),
        ("[[walk.pause]]\nat_m = 10.0\nduration_s = inf\n", "walk.pause[0].duration_s"),
        ("[mounting]\nroll_deg = nan\n", "mounting.roll_deg"),
    ],
)
def test_cli_non_finite_or_negative_seed_exits_2_with_one_line(tmp_path, sim_cli, capsys, text, key):
    f = tmp_path / "bad.toml"
    f.write_text(text)
    assert sim_cli(["--scenario", str(f), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(f) in err and f"'{key}'" in err, err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("args", [["--seed", "-1"], ["--duration-s", "inf"], ["--duration-s", "nan"]])
def test_cli_bad_seed_or_duration_option_exits_2(tmp_path, sim_cli, capsys, args):
    assert sim_cli([*args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "error" in err, err
