"""pyproject.toml declares what `stridefix` needs; requirements.txt is its lock (make deps installs it).

GIVEN both files, THEN every pin of requirements.txt satisfies pyproject's range for that package (in the
dependencies or an extra), every declared package is pinned, and the version comes from VERSION.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11 (the venv's)

REPO = Path(__file__).resolve().parents[3]


def _pins() -> dict[str, str]:
    pins = {}
    for line in (REPO / "requirements.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            m = re.fullmatch(r"([A-Za-z0-9_.\-]+)==(\S+)", line)
            assert m, f"requirements.txt: {line!r} is not NAME==VERSION"
            pins[canonicalize_name(m.group(1))] = m.group(2)
    return pins


def _declared() -> dict[str, Requirement]:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    reqs = [
        *project["dependencies"],
        *(r for extra in project["optional-dependencies"].values() for r in extra),
    ]
    return {canonicalize_name(r.name): r for r in map(Requirement, reqs)}


def test_every_pin_satisfies_the_declared_range():
    pins, declared = _pins(), _declared()
    assert sorted(set(pins) - set(declared)) == []  # a pin nothing declares
    assert sorted(set(declared) - set(pins)) == []  # a dependency make deps would not install
    outside = {n: (pins[n], str(r.specifier)) for n, r in declared.items() if pins[n] not in r.specifier}
    assert outside == {}


def test_runtime_dependencies_cover_the_imports():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    runtime = {canonicalize_name(Requirement(r).name) for r in project["dependencies"]}
    assert {"lcm", "numpy", "scipy", "cantools", "matplotlib", "tqdm"} <= runtime


def test_version_has_one_source():
    doc = tomllib.loads((REPO / "pyproject.toml").read_text())
    assert "version" not in doc["project"] and doc["project"]["dynamic"] == ["version"]
    assert doc["tool"]["setuptools"]["dynamic"]["version"] == {"file": "VERSION"}
    cmake = (REPO / "CMakeLists.txt").read_text()
    assert 'file(STRINGS "${CMAKE_CURRENT_SOURCE_DIR}/VERSION" SF_VERSION_TEXT' in cmake
    assert "project(stridefix VERSION ${SF_VERSION_TEXT}" in cmake
    assert re.fullmatch(r"\d+\.\d+\.\d+\n", (REPO / "VERSION").read_text())


def test_every_package_is_in_the_wheel():
    """A package folder missing from [tool.setuptools] packages is left out of the wheel (the editable
    install of development does not notice)."""
    setuptools = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    found = set()
    for name, folder in setuptools["package-dir"].items():
        root = REPO / folder
        found |= {
            ".".join([name, *init.parent.relative_to(root).parts]) for init in root.rglob("__init__.py")
        }
    assert sorted(found ^ set(setuptools["packages"])) == []
