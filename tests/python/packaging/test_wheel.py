"""The product wheel (`make wheel`, tools/wheel.sh): what a workstation or logger installs without the
source tree.

GIVEN the test build, WHEN tools/wheel.sh builds the wheel from it, THEN the wheel holds the product's
packages, board.dbc, every generated LCM type and the native solver (a platform wheel), and not the
lab. WHEN it is installed into a fresh venv (no pip, no system site-packages; its third-party
dependencies reached through a .pth to this venv's site directory, which holds no StrideFix file),
THEN every StrideFix module imports from that venv, `stridefix --help` has every sub-command available,
and a simulated walk (the DBC from the wheel), replayed by stridefixd, analyzes and reports with the
same metrics as the checkout's analyzer, and exports in latitude/longitude from a site it builds. Beside `cmake --install`'s prefix, the wheel's analyzer finds
the installed stridefixd.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest
from stridefix_analyzer.cli import SUBCOMMANDS

REPO = Path(__file__).resolve().parents[3]
VERSION = (REPO / "VERSION").read_text().strip()
#: every StrideFix module of the product, and where each comes from
PRODUCT_MODULES = (
    "stridefix_common",
    "stridefix_sim",
    "stridefix_analyzer",
    "stridefix",  # the LCM types (generated)
    "stridefix_channels",  # the channel table (generated)
    "stridefix_native",  # the Ceres solver (built)
    "stridefix_native_reference",
)


def _run(cmd: list[str | Path], **kw) -> subprocess.CompletedProcess:
    proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=120, **kw)
    assert proc.returncode == 0, f"{cmd}: {proc.stdout}{proc.stderr}"
    return proc


@pytest.fixture(scope="module")
def wheel(build_dir, tmp_path_factory) -> Path:
    """GIVEN the test build, WHEN tools/wheel.sh (make wheel) runs, THEN its one wheel."""
    dist = tmp_path_factory.mktemp("dist")
    _run([REPO / "tools" / "wheel.sh", build_dir, dist], env={**os.environ, "PY": sys.executable})
    (whl,) = dist.glob("stridefix-*.whl")
    return whl


@pytest.fixture(scope="module")
def fresh_venv(wheel, tmp_path_factory) -> Path:
    """The wheel installed into a new venv; this venv's site directory (third-party packages only) on
    its path after its own."""
    venv = tmp_path_factory.mktemp("venv")
    _run([sys.executable, "-m", "venv", "--without-pip", venv])
    python = venv / "bin" / "python"
    _run([sys.executable, "-m", "pip", "--python", python, "install", "-q", "--no-deps", wheel])
    own = Path(_run([python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"]).stdout.strip())
    (own / "project_third_party.pth").write_text(sysconfig.get_path("purelib") + "\n")
    return venv


def _env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("STRIDEFIXD", "PYTHONPATH", "VIRTUAL_ENV")}
    return {**env, **extra}


def test_wheel_holds_the_product_and_not_the_lab(wheel, build_dir):
    assert wheel.name == f"stridefix-{VERSION}-cp{sys.version_info[0]}{sys.version_info[1]}-" + (
        f"cp{sys.version_info[0]}{sys.version_info[1]}-{sysconfig.get_platform().replace('-', '_')}.whl"
    )
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        dbc = z.read("stridefix_common/board.dbc")
        meta = z.read(f"stridefix-{VERSION}.dist-info/METADATA").decode()
        scripts = z.read(f"stridefix-{VERSION}.dist-info/entry_points.txt").decode()
    assert dbc == (REPO / "firmware" / "board.dbc").read_bytes()
    types = {f"stridefix/{p.stem}.py" for p in (REPO / "lcmtypes" / "stridefix").glob("*.lcm")}
    assert len(types) >= 14 and types | {"stridefix/__init__.py", "stridefix_channels.py"} <= names
    native = {p.name for p in (build_dir / "analyzer" / "native").glob("stridefix_native*.so")}
    assert len(native) == 1 and native | {"stridefix_native_reference.py"} <= names
    assert {n.split("/")[0] for n in names if "/" in n} == {
        "stridefix_common",
        "stridefix_sim",
        "stridefix_analyzer",
        "stridefix",
        f"stridefix-{VERSION}.dist-info",
    }
    assert "Requires-Python: >=3.11" in meta.splitlines()
    assert [line for line in scripts.splitlines() if "=" in line] == [
        "stridefix = stridefix_analyzer.cli:main"
    ]


def test_fresh_venv_runs_the_product_from_the_wheel(fresh_venv, stridefixd, tmp_path):
    python, exe = fresh_venv / "bin" / "python", fresh_venv / "bin" / "stridefix"
    env = _env(PATH=f"{fresh_venv / 'bin'}{os.pathsep}/usr/bin{os.pathsep}/bin")
    code = (
        "import importlib, importlib.util, json, sys; from stridefix_sim.board import DBC_PATH; "
        f"mods = {{m: importlib.import_module(m).__file__ for m in {PRODUCT_MODULES!r}}}; "
        "print(json.dumps([mods, str(DBC_PATH), importlib.util.find_spec('stridefix_lab') is None]))"
    )
    files, dbc, no_lab = json.loads(_run([python, "-c", code], env=env, cwd=tmp_path).stdout)
    assert all(Path(f).is_relative_to(fresh_venv) for f in files.values()), files
    assert (
        Path(dbc).is_relative_to(fresh_venv)
        and Path(dbc).read_bytes() == (REPO / "firmware/board.dbc").read_bytes()
    )
    assert no_lab

    helped = _run([exe, "--help"], env=env, cwd=tmp_path).stdout
    assert "unavailable" not in helped
    assert all(f"    {name} " in helped for name in SUBCOMMANDS)

    walk = tmp_path / "walk"
    _run([exe, "-q", "sim", "--out", walk, "--duration-s", "60"], env=env, cwd=tmp_path)
    summary = json.loads((walk / "sim_summary.json").read_text())
    _run([stridefixd, "--input", walk / "board.candump", "--log", walk / "run.lcmlog", "-q"])
    an = tmp_path / "an"
    _run(
        [exe, "-q", "analyze", walk / "run.lcmlog", walk / "truth.lcmlog", "--out", an], env=env, cwd=tmp_path
    )
    _run([exe, "-q", "report", an], env=env, cwd=tmp_path)
    metrics = json.loads((an / "metrics.json").read_text())
    assert metrics["n_truth"] == 601  # 60 s of truth at 10 Hz
    assert metrics["steps"]["truth"] == summary["steps"] > 80
    assert abs(metrics["steps"]["error"]) <= 2
    assert (an / "report.html").stat().st_size > 50_000
    # the wheel's analyzer computes what the checkout's does
    ref = tmp_path / "ref"
    _run(
        [
            Path(sys.executable).with_name("stridefix"),
            "-q",
            "analyze",
            walk / "run.lcmlog",
            walk / "truth.lcmlog",
            "--out",
            ref,
        ]
    )
    assert json.loads((ref / "metrics.json").read_text()) == metrics
    # and it builds a geo-referenced site from the walk and exports the walk in latitude/longitude
    site = tmp_path / "walk.sfsite"
    _run(
        [exe, "radiomap", "build", walk / "run.lcmlog", walk / "truth.lcmlog", "--mode", "walk"]
        + ["--min-count", "1", "--origin-deg", "47.3769,8.5417", "--out", site],
        env=env,
        cwd=tmp_path,
    )
    track = tmp_path / "walk.geojson"
    _run([exe, "export", walk / "run.lcmlog", "--site", site, "--out", track], env=env, cwd=tmp_path)
    (feature, *_) = json.loads(track.read_text())["features"]
    lon, lat = feature["geometry"]["coordinates"][0][:2]
    assert abs(lat - 47.3769) < 0.01 and abs(lon - 8.5417) < 0.01  # near the origin: a 60 s walk


def test_wheel_runs_with_the_installed_stridefixd(fresh_venv, prefix, tmp_path):
    """GIVEN `cmake --install` into a prefix P and no $STRIDEFIXD, THEN the wheel's `stridefix --version`
    names the version (from the wheel's metadata) and the stridefixd on PATH, P/bin's."""
    env = _env(PATH=f"{prefix / 'bin'}{os.pathsep}/usr/bin{os.pathsep}/bin")
    text = _run([fresh_venv / "bin" / "stridefix", "--version"], env=env, cwd=tmp_path).stdout
    first, second = text.splitlines()
    assert first == f"stridefix {VERSION} (analyzer)"
    assert second.startswith(f"stridefixd {VERSION} (board.dbc sha256 ")
    assert second.endswith(f" at {prefix / 'bin' / 'stridefixd'}")
