"""The example config a logger installs (firmware/examples/stridefixd.ini) cannot drift from the firmware.

GIVEN the example and the built stridefixd's parameter table (--print-config --json), THEN every key of
the example is a parameter, stridefixd accepts the file, and the effective values are the example's;
the /etc/default example feeds the unit the config's installed path.
"""

from __future__ import annotations

import configparser
import json
import re
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
EXAMPLE = REPO / "firmware" / "examples" / "stridefixd.ini"
DEFAULT_FILE = REPO / "firmware" / "examples" / "stridefixd.default"
UNIT = REPO / "tools" / "systemd" / "stridefixd.service"
INSTALLED_CONFIG = "/etc/stridefix/stridefixd.ini"


def _ini(text: str) -> dict[str, str]:
    cp = configparser.ConfigParser(comment_prefixes=("#",), interpolation=None)
    cp.read_string(text)
    return {f"{s}.{k}": v for s in cp.sections() for k, v in cp[s].items()}


def _table(stridefixd: Path) -> dict[str, dict]:
    proc = subprocess.run(
        [str(stridefixd), "--print-config", "--json"], capture_output=True, text=True, timeout=30
    )
    assert proc.returncode == 0, proc.stderr
    return {r["key"]: r for r in json.loads(proc.stdout)["params"]}


def test_every_example_key_is_a_parameter_in_range(stridefixd):
    table, example = _table(stridefixd), _ini(EXAMPLE.read_text())
    assert len(example) >= 10
    assert sorted(set(example) - set(table)) == []
    for key, value in example.items():
        lo, hi = table[key].get("min"), table[key].get("max")
        assert lo is None or float(value) >= lo, key
        assert hi is None or float(value) <= hi, key


def test_stridefixd_takes_the_example(stridefixd):
    proc = subprocess.run(
        [str(stridefixd), "--config", str(EXAMPLE), "--print-config"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert proc.returncode == 0, proc.stderr
    effective = _ini(proc.stdout)
    for key, value in _ini(EXAMPLE.read_text()).items():
        assert float(effective[key]) == float(value), key
    # what the example changes: rotation by size and age (off by default)
    assert float(effective["output.log_rotate_mb"]) == 256 and float(effective["output.log_rotate_s"]) == 3600


def test_default_file_passes_the_installed_config_to_the_unit():
    env = dict(re.findall(r"^(STRIDEFIXD_\w+)=(.*)$", DEFAULT_FILE.read_text(), re.MULTILINE))
    assert env["STRIDEFIXD_INPUT"] == "socketcan:can0"
    assert f"--config {INSTALLED_CONFIG}" in env["STRIDEFIXD_OPTS"]
    unit = UNIT.read_text()
    assert "EnvironmentFile=-/etc/default/stridefixd" in unit and "$STRIDEFIXD_OPTS" in unit
