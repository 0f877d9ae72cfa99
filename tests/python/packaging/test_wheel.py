"""The analyzer as a wheel beside `cmake --install`'s prefix: what a logger or workstation runs without
the source tree.

GIVEN the package's sources copied out of the checkout (the build writes into its source folder), WHEN a
wheel is built and installed into a scratch folder T (no dependencies: this venv has them) and
`stridefix --version` runs from T with the install's site directory and P/bin on the path and no
$STRIDEFIXD, THEN the analyzer imports from T, its version is VERSION (from the wheel's metadata) and it
finds the installed stridefixd.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
VERSION = (REPO / "VERSION").read_text().strip()


def test_wheel_runs_with_the_installed_stridefixd(prefix, python_site, tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    for rel in ("pyproject.toml", "VERSION"):
        shutil.copy2(REPO / rel, src / rel)
    for pkg in (
        "common/stridefix_common",
        "analyzer/stridefix_analyzer",
        "hil-sim/stridefix_sim",
        "lab/stridefix_lab",
    ):
        shutil.copytree(REPO / pkg, src / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]
    wheels = tmp_path / "wheels"
    built = subprocess.run(
        [*pip, "wheel", "--no-deps", "--no-build-isolation", str(src), "-w", str(wheels)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert built.returncode == 0, built.stderr
    (wheel,) = wheels.glob("stridefix-*.whl")
    assert wheel.name.startswith(f"stridefix-{VERSION}-")
    target = tmp_path / "site"
    installed = subprocess.run(
        [*pip, "install", "--no-deps", "--target", str(target), str(wheel)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert installed.returncode == 0, installed.stderr

    env = {k: v for k, v in os.environ.items() if k not in ("STRIDEFIXD", "PYTHONPATH")}
    env["PYTHONPATH"] = f"{target}{os.pathsep}{python_site}"
    env["PATH"] = f"{prefix / 'bin'}{os.pathsep}/usr/bin{os.pathsep}/bin"
    code = (
        "import json, stridefix_analyzer, stridefix; from stridefix_analyzer.cliapp import version_text; "
        "print(json.dumps([stridefix_analyzer.__file__, stridefix.__file__, version_text()]))"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=env, cwd=tmp_path
    )
    assert proc.returncode == 0, proc.stderr
    analyzer_file, types_file, text = json.loads(proc.stdout)
    assert Path(analyzer_file).is_relative_to(target) and Path(types_file).is_relative_to(python_site)
    first, second = text.splitlines()
    assert first == f"stridefix {VERSION} (analyzer)"
    assert second.startswith(f"stridefixd {VERSION} (board.dbc sha256 ")
    assert second.endswith(f" at {prefix / 'bin' / 'stridefixd'}")
