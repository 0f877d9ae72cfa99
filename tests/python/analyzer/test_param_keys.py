"""Every firmware parameter key the analyzer and the lab spell (tuning candidates, benchmark overrides) is a key
of the firmware's own table (`stridefixd --print-config --json`): renaming a parameter in
firmware/core/sf_params.h fails here, not halfway through a benchmark."""

from __future__ import annotations

import re
from pathlib import Path

from stridefix_analyzer.firmware import Firmware

REPO = Path(__file__).resolve().parents[3]
#: the packages that spell keys: the analyzer and the lab
ROOTS = (REPO / "analyzer" / "stridefix_analyzer", REPO / "lab" / "stridefix_lab")
# a string literal (or f-string) that starts with section.name= : a --set override
_SET_LITERAL = re.compile(r"""f?["']([a-z][a-z0-9_]*\.[a-z][a-z0-9_]*)=""")


def _spelled_keys() -> dict[str, list[str]]:
    keys: dict[str, list[str]] = {}
    for path in sorted(p for root in ROOTS for p in root.rglob("*.py")):
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for key in _SET_LITERAL.findall(line):
                keys.setdefault(key, []).append(f"{path.relative_to(REPO)}:{n}")
    return keys


def test_the_scan_finds_the_tuning_rows():
    keys = _spelled_keys()
    assert {"heading.learn_offset", "fingerprint.powed_beta", "fusion.acc_wifi_scale"} <= set(keys)


def test_every_spelled_key_is_a_firmware_parameter(stridefixd):
    known = Firmware(stridefixd).params
    unknown = {k: where for k, where in _spelled_keys().items() if k not in known}
    assert unknown == {}
