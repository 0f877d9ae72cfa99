"""The Firmware runner and the scheme registry: one source for parameter keys and scheme ids."""

from __future__ import annotations

import pytest
from stridefix import pose_t
from stridefix_analyzer import schemes
from stridefix_analyzer.firmware import Firmware, FirmwareError


def test_schemes_come_from_the_lcm_constants():
    consts = {k[len("SCHEME_") :].lower(): v for k, v in vars(pose_t).items() if k.startswith("SCHEME_")}
    assert {s.name: s.id for s in schemes.SCHEMES} == consts
    assert [s.id for s in schemes.SCHEMES] == sorted(consts.values())
    assert schemes.scheme_code("kalman") == pose_t.SCHEME_KALMAN and schemes.scheme_code("4") == 4
    assert (
        schemes.scheme_name(pose_t.SCHEME_ADAPTIVE) == "adaptive" and schemes.scheme_name(99) == "scheme_99"
    )
    assert len({s.colour for s in schemes.SCHEMES}) == len(schemes.SCHEMES)
    with pytest.raises(schemes.UnknownSchemeError, match="known"):
        schemes.scheme_code("nope")


def test_firmware_params_and_set_checks(stridefixd):
    fw = Firmware(stridefixd)
    assert "init.floor" in fw.params and "output.scheme" in fw.params
    assert (fw.params["init.floor"].min, fw.params["init.floor"].max) == (-20, 200)
    assert fw.check_sets(["init.floor=1"]) == ["init.floor=1"]
    with pytest.raises(FirmwareError, match="unknown key"):
        fw.check_sets(["init.flor=1"])
    with pytest.raises(FirmwareError, match="init.floor"):
        fw.check_sets(["init.floor=9999"])


def test_firmware_run_names_the_command_on_failure(stridefixd, tmp_path):
    fw = Firmware(stridefixd)
    with pytest.raises(FirmwareError, match="stridefixd exit 2: .*missing.candump"):
        fw.run(input=tmp_path / "missing.candump", log=tmp_path / "x.lcmlog")
    with pytest.raises(FirmwareError, match="exactly one"):
        fw.command(log="x")
    with pytest.raises(FirmwareError, match="not found"):
        Firmware(tmp_path / "nothing").run(input="a", log="b")
