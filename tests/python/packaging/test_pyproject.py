"""pyproject.toml declares what `stridefix` needs; requirements.txt is its lock (make deps installs it).

GIVEN both files, THEN every pin of requirements.txt satisfies pyproject's range for that package (in the
dependencies or an extra), every declared package is pinned, and the version comes from VERSION. The
product and the lab (lab/pyproject.toml) are two distributions that share the package folders out
between them, and one Python floor holds for both, ruff and mypy.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name

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


def test_product_and_lab_share_the_packages_out():
    """The product wheel holds every package but the lab's; the lab's distribution holds the lab."""
    product = tomllib.loads((REPO / "pyproject.toml").read_text())
    lab = tomllib.loads((REPO / "lab" / "pyproject.toml").read_text())
    assert set(product["tool"]["setuptools"]["package-dir"]) == {
        "stridefix_common",
        "stridefix_sim",
        "stridefix_analyzer",
    }
    assert not any(p.startswith("stridefix_lab") for p in product["tool"]["setuptools"]["packages"])
    assert lab["tool"]["setuptools"]["packages"]["find"]["include"] == ["stridefix_lab*"]
    assert set(product["project"]["scripts"]) == {"stridefix"}
    assert lab["project"]["scripts"] == {"stridefix-lab": "stridefix_lab.cli:main"}
    assert [Requirement(r).name for r in lab["project"]["dependencies"]] == ["stridefix"]
    assert (REPO / "lab" / "VERSION").read_text() == (REPO / "VERSION").read_text()
    assert product["tool"]["setuptools"]["package-data"] == {
        "stridefix_common": ["board.dbc", "site_ranges.tsv"]
    }
    ranges = REPO / "common" / "stridefix_common" / "site_ranges.tsv"
    assert ranges.resolve() == (REPO / "firmware" / "site_ranges.tsv").resolve()
    dbc = REPO / "common" / "stridefix_common" / "board.dbc"
    assert dbc.resolve() == (REPO / "firmware" / "board.dbc").resolve()


def test_one_python_floor():
    """The modules use 3.11 (tomllib): both distributions require it, ruff and mypy check for it."""
    product = tomllib.loads((REPO / "pyproject.toml").read_text())
    lab = tomllib.loads((REPO / "lab" / "pyproject.toml").read_text())
    floor = SpecifierSet(product["project"]["requires-python"])
    assert str(floor) == ">=3.11" == lab["project"]["requires-python"]
    assert "3.10" not in floor and "3.11" in floor
    assert product["tool"]["ruff"]["target-version"] == "py311"
    assert product["tool"]["mypy"]["python_version"] == "3.11"
