"""The product wheel: pyproject.toml's packages plus what the CMake build generates for Python.

``make wheel`` (tools/wheel.sh) builds ``dist/stridefix-<version>-*.whl`` from a built tree. Besides the
packages pyproject.toml lists (``stridefix_common`` with ``board.dbc``, ``stridefix_sim``,
``stridefix_analyzer``), the wheel carries from the CMake build directory ($STRIDEFIX_BUILD, default
``build/`` beside this file):

- the LCM Python types: the package ``stridefix`` and the module ``stridefix_channels``
  (``BUILD/lcmtypes/python``); required, the product imports them everywhere;
- the native solver ``stridefix_native`` with its scipy twin ``stridefix_native_reference``
  (``BUILD/analyzer/native``), when the build made it; the wheel is then a platform wheel
  (``cp311-cp311-linux_x86_64``), else a pure one whose crowd solvers fall back to scipy.

An editable install (``make deps``) takes none of them: the venv imports them from the build through
the .pth file tools/deps.sh writes, so a rebuild needs no reinstall.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


def cmake_build() -> Path:
    return Path(os.environ.get("STRIDEFIX_BUILD") or HERE / "build").resolve()


def native_files(build: Path) -> list[Path]:
    """The native module and its reference twin, when the build made the module."""
    native = build / "analyzer" / "native"
    modules = sorted(native.glob("stridefix_native.*.so"))
    return [*modules, native / "stridefix_native_reference.py"] if modules else []


def generated_files(build: Path) -> list[tuple[Path, str]]:
    """(file in the build, path in the wheel) of everything generated the product imports. Exits with
    one message when the build has no LCM types."""
    types = build / "lcmtypes" / "python"
    if not (types / "stridefix" / "__init__.py").is_file() or not (types / "stridefix_channels.py").is_file():
        sys.exit(
            f"stridefix wheel: no generated LCM types in {types}: run `make build` first "
            "(or set STRIDEFIX_BUILD to the CMake build directory)"
        )
    files = [(p, f"stridefix/{p.name}") for p in sorted((types / "stridefix").glob("*.py"))]
    files.append((types / "stridefix_channels.py", "stridefix_channels.py"))
    return files + [(p, p.name) for p in native_files(build)]


class BuildPyWithGenerated(build_py):
    """build_py, then the build's generated files copied beside the packages (not when editable)."""

    def run(self) -> None:
        super().run()
        if self.editable_mode:
            return
        for src, rel in generated_files(cmake_build()):
            dest = Path(self.build_lib) / rel
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest)


class ProductDistribution(Distribution):
    """A platform wheel when it carries the native module (a compiled extension, built by CMake)."""

    def has_ext_modules(self) -> bool:
        return bool(native_files(cmake_build()))


setup(cmdclass={"build_py": BuildPyWithGenerated}, distclass=ProductDistribution)
