"""Fixtures of the packaging tests: the test build installed into a scratch prefix (`cmake --install`)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def build_dir(stridefixd) -> Path:
    """The CMake build the tests run (STRIDEFIXD is BUILD/firmware/stridefixd)."""
    build = Path(stridefixd).resolve().parents[1]
    if not (build / "cmake_install.cmake").is_file():
        pytest.fail(f"{build}: not a CMake build directory (no cmake_install.cmake)")
    return build


@pytest.fixture(scope="session")
def prefix(build_dir, tmp_path_factory) -> Path:
    """GIVEN the test build, WHEN `cmake --install BUILD --prefix P` runs, THEN P is returned."""
    cmake = shutil.which("cmake")
    if cmake is None:
        pytest.fail("cmake is not on PATH")
    p = tmp_path_factory.mktemp("prefix")
    proc = subprocess.run(
        [cmake, "--install", str(build_dir), "--prefix", str(p)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return p


@pytest.fixture(scope="session")
def python_site(prefix, build_dir) -> Path:
    """Where the install put the LCM Python types (the build's SF_INSTALL_PYTHONDIR under the prefix)."""
    cache = (build_dir / "CMakeCache.txt").read_text()
    rel = next(
        line.split("=", 1)[1] for line in cache.splitlines() if line.startswith("SF_INSTALL_PYTHONDIR:")
    )
    return Path(rel) if os.path.isabs(rel) else prefix / rel
