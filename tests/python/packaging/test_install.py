"""`cmake --install` : what a logger and a user of the core library get.

GIVEN the test build (STRIDEFIXD's build directory) installed into a scratch prefix P, THEN P holds the
daemon, the core library with its public headers and pkg-config file, the DBC, the LCM definitions and
their C headers and Python types, the example configs, the systemd unit and the man page; the installed
daemon runs, its version is the repository's VERSION, the unit verifies (systemd-analyze) and the man
page renders (man -l / groff); a C program builds against the installed core alone.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
VERSION = (REPO / "VERSION").read_text().strip()

# relative to the prefix; lib/ is GNUInstallDirs' libdir for a prefix outside /usr (the tests' scratch one)
FILES = [
    "bin/stridefixd",
    "lib/libsf_core.a",
    "lib/libsf_lcmtypes.a",
    "lib/pkgconfig/stridefix-core.pc",
    "include/stridefix/sf_estimator.h",
    "include/stridefix/sf_params.h",
    "include/stridefix/sf_schemes.h",
    "include/stridefix/lcmtypes/stridefix_pose_t.h",
    "include/stridefix/lcmtypes/sf_channels.h",
    "share/stridefix/board.dbc",
    "share/stridefix/lcmtypes/pose_t.lcm",
    "share/stridefix/lcmtypes/channels.csv",
    "share/stridefix/examples/stridefixd.ini",
    "share/stridefix/examples/stridefixd.default",
    "share/stridefix/examples/stridefixd-defaults.ini",
    "lib/systemd/system/stridefixd.service",
]


def _run(*cmd: str | Path, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=60, **kw)


def test_install_puts_every_file(prefix):
    missing = [f for f in FILES if not (prefix / f).is_file()]
    assert missing == []
    # every .lcm of the tree, every public core header, no internal one
    lcm = {p.name for p in (REPO / "lcmtypes" / "stridefix").glob("*.lcm")}
    assert {p.name for p in (prefix / "share/stridefix/lcmtypes").glob("*.lcm")} == lcm
    public = {p.name for p in (REPO / "firmware/core").glob("sf_*.h") if not p.name.endswith("_internal.h")}
    installed = {p.name for p in (prefix / "include/stridefix").glob("*.h")}
    assert installed == public | {"sf_schemes.h"}
    assert (
        len(
            {f"stridefix_{n[:-4]}.h" for n in lcm}
            - {p.name for p in (prefix / "include/stridefix/lcmtypes").glob("*.h")}
        )
        == 0
    )
    assert (prefix / "share/stridefix/board.dbc").read_bytes() == (REPO / "firmware/board.dbc").read_bytes()


def test_installed_stridefixd_runs_help_and_version(prefix):
    exe = prefix / "bin" / "stridefixd"
    helped = _run(exe, "--help")
    assert helped.returncode == 0 and helped.stdout.startswith("Usage: stridefixd")
    version = _run(exe, "--version")
    assert version.returncode == 0
    assert re.match(
        rf"stridefixd {re.escape(VERSION)} \(board.dbc sha256 [0-9a-f]{{64}}\)$", version.stdout.strip()
    )


def test_defaults_ini_is_print_config(prefix):
    printed = _run(prefix / "bin" / "stridefixd", "--print-config").stdout
    assert (prefix / "share/stridefix/examples/stridefixd-defaults.ini").read_text() == printed


def test_one_version_everywhere(prefix, stridefixd):
    """VERSION = stridefixd's = the analyzer's = `stridefix --version`'s = the pkg-config file's."""
    from stridefix_analyzer import __version__
    from stridefix_analyzer.cliapp import version_text

    assert __version__ == VERSION
    lines = version_text().splitlines()
    assert lines[0] == f"stridefix {VERSION} (analyzer)"
    assert lines[1].startswith(f"stridefixd {VERSION} ") and str(stridefixd) in lines[1]
    pc = (prefix / "lib/pkgconfig/stridefix-core.pc").read_text()
    assert f"\nVersion: {VERSION}\n" in pc


def test_lcm_python_types_import_from_the_prefix(python_site, build_dir):
    """The installed `stridefix` package and `stridefix_channels` are the build's, importable from P."""
    code = (
        "import json, stridefix, stridefix_channels; from stridefix import pose_t; "
        "print(json.dumps([stridefix.__file__, stridefix_channels.__file__, pose_t._get_packed_fingerprint().hex()]))"
    )
    proc = _run(sys.executable, "-c", code, env={"PYTHONPATH": str(python_site), "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 0, proc.stderr
    pkg, channels, fingerprint = json.loads(proc.stdout)
    assert Path(pkg).is_relative_to(python_site) and Path(channels).is_relative_to(python_site)
    built = _run(
        sys.executable,
        "-c",
        "from stridefix import pose_t; print(pose_t._get_packed_fingerprint().hex())",
        env={"PYTHONPATH": str(build_dir / "lcmtypes" / "python"), "PATH": "/usr/bin:/bin"},
    )
    assert built.stdout.strip() == fingerprint


def test_a_program_builds_against_the_installed_core(prefix, tmp_path, stridefixd):
    """pkg-config's flags alone (no source tree): the core's defaults are the firmware's parameter table."""
    cc, pkg_config = shutil.which("cc"), shutil.which("pkg-config")
    if cc is None or pkg_config is None:
        pytest.skip("no cc or pkg-config here")
    flags = _run(
        pkg_config,
        "--cflags",
        "--libs",
        "stridefix-core",
        env={"PKG_CONFIG_PATH": str(prefix / "lib/pkgconfig")},
    )
    assert flags.returncode == 0, flags.stderr
    src = tmp_path / "use_core.c"
    src.write_text(
        '#include <stdio.h>\n#include "sf_estimator.h"\nstatic sf_estimator_t est;\n'
        "int main(void) { sf_params_t p; sf_params_default(&p); sf_estimator_init(&est, &p);\n"
        '  printf("%.17g\\n", p.stride_weinberg_k); return 0; }\n'
    )
    exe = tmp_path / "use_core"
    built = _run(cc, "-std=c11", "-Wall", "-Werror", src, *flags.stdout.split(), "-o", exe)
    assert built.returncode == 0, built.stderr
    table = json.loads(_run(stridefixd, "--print-config", "--json").stdout)["params"]
    default_k = next(float(r["default"]) for r in table if r["key"] == "stride.weinberg_k")
    assert float(_run(exe).stdout) == default_k


def test_lcm_c_headers_compile_alone(prefix, tmp_path):
    cc = shutil.which("cc")
    if cc is None:
        pytest.skip("no cc here")
    src = tmp_path / "use_types.c"
    src.write_text('#include "stridefix_pose_t.h"\n#include "sf_channels.h"\nint main(void) { return 0; }\n')
    proc = _run(cc, "-std=c11", "-fsyntax-only", f"-I{prefix}/include/stridefix/lcmtypes", src)
    assert proc.returncode == 0, proc.stderr


def test_installed_unit_runs_the_installed_binary_and_verifies(prefix):
    unit = prefix / "lib/systemd/system/stridefixd.service"
    exec_start = re.search(r"^ExecStart=(\S+)", unit.read_text(), re.MULTILINE)
    assert exec_start and exec_start.group(1) == str(prefix / "bin" / "stridefixd")
    if shutil.which("systemd-analyze") is None:
        pytest.skip("systemd-analyze is not installed here")
    proc = _run("systemd-analyze", "verify", unit)
    assert proc.returncode == 0, proc.stderr
    assert [line for line in proc.stderr.splitlines() if unit.name in line] == []


def test_man_page_renders(prefix):
    page = prefix / "share/man/man1/stridefixd.1"
    if not page.is_file():
        if shutil.which("help2man") is None:
            pytest.skip(
                "help2man is not installed here (make deps installs it), so the build made no man page"
            )
        pytest.fail(f"{page} not installed although help2man is on PATH (reconfigure the build)")
    if shutil.which("man"):
        proc = _run("man", "-l", "-P", "cat", page, env={"MANWIDTH": "100", "PATH": "/usr/bin:/bin"})
    elif shutil.which("groff"):
        proc = _run("groff", "-man", "-Tutf8", page)
    else:
        pytest.skip("neither man nor groff here")
    assert proc.returncode == 0, proc.stderr
    text = re.sub(r".\x08", "", proc.stdout)  # overstrike bold
    for section in ("NAME", "SYNOPSIS", "DESCRIPTION", "FILES", "SEE ALSO"):
        assert re.search(rf"^{section}$", text, re.MULTILINE), section
    assert (
        f"stridefixd {VERSION}" in text
        and "--print-config" in text
        and "/etc/stridefix/stridefixd.ini" in text
    )
    # every long option of --help is in the page (it is made from --help)
    options = set(
        re.findall(r"^\s+(?:-\w, )?(--[a-z-]+)", _run(prefix / "bin" / "stridefixd", "--help").stdout, re.M)
    )
    assert {"--speed", "--replay", "--channels"} <= options
    assert sorted(o for o in options if o not in text.replace("\u2010", "-")) == []
