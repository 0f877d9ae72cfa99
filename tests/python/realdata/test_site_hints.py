"""A replay without a site says that the fused schemes need one, and how to build it: stridefixd once
on stderr, stridefix analyze once on the log it wrote; `stridefix site` refuses what it cannot read
with one line and exit status 2."""

from __future__ import annotations

import subprocess
import sys

from stridefix_analyzer.scoring.analyze import NO_SITE_NOTE


def _stridefix(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "stridefix_analyzer.cli", *args], capture_output=True, text=True, timeout=300
    )


def test_site_less_replay_says_a_site_is_needed(tmp_path, stridefixd, real_trace):
    # GIVEN a real walk imported
    walk = tmp_path / "walk.lcmlog"
    assert _stridefix("import", "msindoor", str(real_trace), "-o", str(walk)).returncode == 0
    # WHEN it is replayed without --site and analyzed
    fw = subprocess.run(
        [
            str(stridefixd),
            "--replay",
            str(walk),
            "--set",
            "magcal.enable=0",
            "--log",
            str(tmp_path / "run.lcmlog"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    an = _stridefix("analyze", str(tmp_path / "run.lcmlog"), str(walk), "--out", str(tmp_path / "an"))
    # THEN both succeed and each says once that the fused schemes need a site and names `stridefix site`
    assert fw.returncode == 0, fw.stderr
    hint = [line for line in fw.stderr.splitlines() if "no --site" in line]
    assert len(hint) == 1 and "stridefix site" in hint[0], fw.stderr
    assert an.returncode == 0, an.stderr
    assert an.stderr.count(NO_SITE_NOTE) == 1 and "stridefix site" in NO_SITE_NOTE


def test_site_refuses_a_missing_walk_with_one_line(tmp_path, stridefixd):
    # WHEN `stridefix site` is given a walk that is not there
    proc = _stridefix(
        "site",
        str(tmp_path / "absent.lcmlog"),
        "--out",
        str(tmp_path / "s.sfsite"),
        "--stridefixd",
        str(stridefixd),
    )
    # THEN it exits 2 with one line naming the file, and writes nothing
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "absent.lcmlog" in lines[0] and "Traceback" not in proc.stderr
    assert not (tmp_path / "s.sfsite").exists() and not (tmp_path / "s.ini").exists()


def test_site_help_names_what_it_learns():
    proc = _stridefix("site", "--help")
    assert proc.returncode == 0
    for word in ("--floor-plan", "--building", "--format", "SITE.ini", "rotation", "Weinberg"):
        assert word in proc.stdout, word
