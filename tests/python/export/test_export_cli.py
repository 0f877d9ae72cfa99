"""`stridefix export`'s usage and errors: one message naming the file or option, the exit status of
stridefix_common.exits, no traceback."""

from __future__ import annotations

import subprocess
import sys

import pytest
from stridefix_analyzer.io.sitefile import read_site, write_site
from stridefix_common.exits import EXIT_FAILURE, EXIT_NOTHING_VALID, EXIT_OK, EXIT_USAGE


def _one_error(proc, status, *words):
    assert proc.returncode == status, (proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("stridefix export: error: "), proc.stderr
    for word in words:
        assert word in lines[0]


def test_help(cli):
    proc = cli("export", "--help")
    assert proc.returncode == EXIT_OK
    for option in ("--site", "--out", "--format", "--scheme", "--start-utc", "geojson", "mcap"):
        assert option in proc.stdout


@pytest.mark.parametrize("suffix", ["geojson", "gpx", "kml"])
def test_a_site_without_geo_reference_says_how_to_give_one(cli, geo_walk, tmp_path, suffix):
    site = read_site(geo_walk["site"])
    site.has_geo = False
    write_site(tmp_path / "nogeo.sfsite", site)
    out = tmp_path / f"walk.{suffix}"
    proc = cli("export", str(geo_walk["log"]), "--site", str(tmp_path / "nogeo.sfsite"), "--out", str(out))
    _one_error(proc, EXIT_USAGE, "nogeo.sfsite", "needs a geo-reference", "--origin-deg", "[geo]")
    assert not out.exists()


def test_bad_inputs(cli, geo_walk, tmp_path):
    log, site = str(geo_walk["log"]), str(geo_walk["site"])
    out = str(tmp_path / "walk.geojson")
    _one_error(cli("export", log, "--site", site, "--out", out, "--scheme", "nope"), EXIT_USAGE, "nope")
    _one_error(
        cli("export", str(tmp_path / "missing.lcmlog"), "--site", site, "--out", out),
        EXIT_USAGE,
        "missing.lcmlog",
    )
    _one_error(
        cli("export", log, "--site", str(tmp_path / "none.sfsite"), "--out", out), EXIT_USAGE, "none.sfsite"
    )
    _one_error(
        cli("export", log, "--site", site, "--out", str(tmp_path / "walk.txt")), EXIT_USAGE, "--format"
    )
    junk = tmp_path / "junk.lcmlog"
    junk.write_bytes(b"not an LCM log at all\n" * 10)
    _one_error(cli("export", str(junk), "--site", site, "--out", out), EXIT_NOTHING_VALID, "junk.lcmlog")
    # a log without any pose: read, but nothing to export
    _one_error(
        cli("export", str(geo_walk["truth"]), "--site", site, "--out", out), EXIT_NOTHING_VALID, "no POSE"
    )
    empty_mcap = tmp_path / "truth.mcap"
    _one_error(
        cli("export", str(geo_walk["truth"]), "--site", site, "--out", str(empty_mcap)),
        EXIT_NOTHING_VALID,
        "nothing to export",
    )
    assert not empty_mcap.exists()
    unwritable = str(tmp_path / "no" / "such" / "dir" / "walk.gpx")
    _one_error(cli("export", log, "--site", site, "--out", unwritable), EXIT_FAILURE, "cannot write")
    bad_time = cli("export", log, "--site", site, "--out", out, "--start-utc", "yesterday")
    assert bad_time.returncode == EXIT_USAGE and "ISO 8601" in bad_time.stderr


def test_format_option_beats_the_suffix(cli, geo_walk, tmp_path):
    out = tmp_path / "walk.txt"
    proc = cli(
        "export", str(geo_walk["log"]), "--site", str(geo_walk["site"]), "--out", str(out), "--format", "gpx"
    )
    assert proc.returncode == EXIT_OK, proc.stderr
    assert out.read_text().lstrip().startswith("<?xml") and "<gpx" in out.read_text()


@pytest.mark.parametrize(("suffix", "module"), [("gpx", "gpxpy"), ("kml", "simplekml"), ("mcap", "mcap")])
def test_a_missing_library_of_the_extra_says_what_to_install(geo_walk, tmp_path, suffix, module):
    # GIVEN the format's library hidden from the import system (as on an install without the extra)
    code = (
        "import sys\n"
        f"for name in ({module!r}, {module + '.gpx'!r}, {module + '.writer'!r}): sys.modules[name] = None\n"
        "from stridefix_analyzer.cli import main\n"
        "sys.exit(main(sys.argv[1:]))\n"
    )
    out = tmp_path / f"walk.{suffix}"
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            code,
            "export",
            str(geo_walk["log"]),
            "--site",
            str(geo_walk["site"]),
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
    )
    # THEN one line names the package and the extra, exit 1 (a failure, not the user's input)
    _one_error(proc, EXIT_FAILURE, module, "pip install 'stridefix[export]'")
    assert not out.exists()
