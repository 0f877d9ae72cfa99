"""Every command's exit contract on hostile inputs: one table, every `stridefix` sub-command and
`stridefix-lab realbench`.

GIVEN an input of each hostile kind (missing, a directory, empty, PNG bytes, UTF-16 text, binary junk,
an LCM log cut inside its first event, text of the command's format with absurd numbers) in each
input position of each command, or a good input with `--out` below a regular file, WHEN the command
runs (in-process, `-q`), THEN it exits with the status of stridefix_common.exits and prints one line on
stderr that names the file, never a traceback.

Regression, the rows that broke: realbench on a folder where no walk imports raised TypeError (exit
1); the importers raised OverflowError on huge times or `FloorName:F9999...`; `--out` below a file
gave a traceback in every command but sim, import, score and export; `import msindoor` of an
empty, PNG or UTF-16 file, and `analyze` / `radiomap build` of an empty file, exited 2 instead of 3;
a building description that is not UTF-8 raised UnicodeDecodeError; `compare` and `report` of a
result file that is not JSON exited 2 (read, nothing valid: 3); `spy --types-jar` of a missing file
exited 1.

Expected status: a missing input or a directory where a file is expected is 2; a data input (LCM
log, trace, result file, estimate file) read but holding nothing valid is 3; a support file (scenario,
building description, site file, Java types jar) that is not one is 2, as stridefixd's --config and
--site are; an output that cannot be written is 1.
"""

from __future__ import annotations

import dataclasses
import random
import subprocess
import zipfile
from pathlib import Path

import pytest
from stridefix_analyzer import cli as stridefix_cli
from stridefix_common.exits import EXIT_FAILURE, EXIT_NOTHING_VALID, EXIT_OK, EXIT_USAGE
from stridefix_lab import cli as lab_cli

KINDS = ("missing", "directory", "empty", "png", "utf16", "junk", "truncated_lcm", "huge_numbers")
#: input formats that are support files: content that is not one is "cannot be read" (2)
SUPPORT = ("scenario", "building", "site", "jar")
#: input formats that are a directory of files
FOLDERS = ("analysis_dir", "floor_dir")
BIG = "9" * 400

GSD_TEXT = "% GetSensorData\nACCE;1.0;2.0;0.1;0.2;9.8;3\nPOSI;1.0;1;49.46;11.11;0;100\n"
TRACE_TEXT = "#\tFloorName:F1\n1000\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n1000\tTYPE_WAYPOINT\t1.0\t2.0\n"
GT_TEXT = "0010.000,2.111,41.461,00,001\n0020.000,2.111,41.4611,01,002\n"
EST_TEXT = "0,0,0,0,0,0,0\n0,0,0,0,0,0,0\n10.000,1.0,0.5,45.0,2.111,41.461,0.0\n"

#: text of each format with valid-looking records and absurd numbers
HUGE = {
    "lcm": f"{BIG}\n",
    "trace": (
        f"#\tFloorName:F{BIG}\n{BIG}\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n"
        f"1{'0' * 30}\tTYPE_MAGNETIC_FIELD\t1\t2\t3\t3\n2000\tTYPE_WIFI\tn\taa:bb:cc:dd:ee:01\t-50\t{BIG}\t1\n"
        f"{BIG}\tTYPE_BEACON\tu\t1\t2\t-60\t-70\t1e308\taa:bb:cc:dd:ee:02\t1\n"
    ),
    "gsd": (
        f"% GetSensorData\nACCE;1e300;1e300;0.1;0.2;9.8;3\nGYRO;{BIG};1;0;0;0;3\nPRES;1e19;1e19;1000;3\n"
        f"WIFI;1.0;1.0;n;aa:bb:cc:dd:ee:01;{BIG};-50\nPOSI;1e300;1;49.46;11.11;{BIG};100\n"
    ),
    "json": f'{{"kind": "stridefix-analyze-metrics", "x": 1{"0" * 5000}}}\n',
    "est": f"0,0,0,0,0,0,0\n0,0,0,0,0,0,0\n1e400,1.0,0.5,45.0,2.111,41.461,{BIG}\n",
    "truth_csv": f"1e400,2.111,41.461,{BIG},001\n",
    "scenario": f"[walk]\nduration_s = 1e{BIG}\n",
    "building": f'format = "stridefix-building 1"\n[[floors]]\nheight_m = 1e{BIG}\n',
    "site": f"{BIG}\n",
    "jar": f"{BIG}\n",
}
#: what a UTF-16 file of each format says (valid content, the wrong encoding)
UTF16 = {"trace": TRACE_TEXT, "gsd": GSD_TEXT, "est": EST_TEXT, "truth_csv": GT_TEXT}


@dataclasses.dataclass(frozen=True)
class Row:
    """A command line with one input under test ({IN}, of format ``fmt``) and maybe an output ({OUT})."""

    name: str
    argv: tuple[str, ...]
    fmt: str
    lab: bool = False
    #: statuses that differ from the default table, by kind
    expect: tuple[tuple[str, int], ...] = ()

    def status(self, kind: str) -> int:
        special = dict(self.expect)
        if kind in special:
            return special[kind]
        if kind == "unwritable_out":
            return EXIT_FAILURE
        if kind in ("missing", "directory"):
            return EXIT_USAGE
        return EXIT_USAGE if self.fmt in SUPPORT else EXIT_NOTHING_VALID


PAIR = "{IN},{TRUTH}"
ROWS = [
    Row("sim", ("sim", "--scenario", "{IN}", "--out", "{OUT}", "--duration-s", "5"), "scenario",
        expect=(("empty", EXIT_OK),)),
    Row("import msindoor", ("import", "msindoor", "{IN}", "--out", "{OUT}"), "trace"),
    Row("import msindoor -o", ("import", "msindoor", "{IN}", "-o", "{OUT}/x.lcmlog", "--json", "{OUT}/s.json"),
        "trace"),
    Row("import gsd", ("import", "gsd", "{IN}", "-o", "{OUT}/x.lcmlog"), "gsd"),
    Row("analyze", ("analyze", "{IN}", "{TRUTH}", "--out", "{OUT}"), "lcm"),
    Row("analyze --tum --csv", ("analyze", "{IN}", "{TRUTH}", "--out", "{TMP}/an", "--tum", "{OUT}/t",
        "--csv", "{OUT}/c"), "lcm"),
    Row("analyze --site", ("analyze", "{LOG}", "{TRUTH}", "--site", "{IN}", "--out", "{OUT}"), "site"),
    Row("report", ("report", "{IN}", "--out", "{OUT}/r.html"), "analysis_dir"),
    Row("compare", ("compare", "{IN}", "{METRICS}", "--out", "{OUT}/c.html"), "json"),
    Row("compare --json", ("compare", "{METRICS}", "{IN}", "--json", "{OUT}/c.json"), "json"),
    # the IPIN scorer is strict, as the organisers' is: a row with a bad number stops it (2)
    Row("score", ("score", "--truth", "{GT}", "{IN}", "--json", "{OUT}/s.json"), "est",
        expect=(("huge_numbers", EXIT_USAGE),)),
    Row("score --truth", ("score", "--truth", "{IN}", "{EST}"), "truth_csv", expect=(("huge_numbers", EXIT_USAGE),)),
    Row("radiomap build", ("radiomap", "build", "{IN}", "{TRUTH}", "--out", "{OUT}/s.sfsite"), "lcm"),
    Row("radiomap build --building", ("radiomap", "build", "{LOG}", "{TRUTH}", "--building", "{IN}", "--out",
        "{OUT}/s.sfsite"), "building"),
    Row("radiomap show", ("radiomap", "show", "{IN}", "--png", "{OUT}/s.png"), "site"),
    Row("site", ("site", PAIR, "--no-learn", "--out", "{OUT}/s.sfsite", "--config-out", "{OUT}/s.ini"), "lcm"),
    Row("crowd fit", ("crowd", "fit", PAIR, "--scheduler", "serial", "--out", "{OUT}"), "lcm"),
    Row("crowd solve", ("crowd", "solve", PAIR, "--out", "{OUT}"), "lcm"),
    Row("crowd radiomap", ("crowd", "radiomap", PAIR, "--out", "{OUT}/s.sfsite"), "lcm"),
    Row("export", ("export", "{IN}", "--site", "{SITE}", "--out", "{OUT}/e.geojson"), "lcm"),
    Row("export --site", ("export", "{LOG}", "--site", "{IN}", "--out", "{OUT}/e.geojson"), "site"),
    Row("live --site", ("live", "--lcm-url", "memq://", "--site", "{IN}", "--port", "0"), "site"),
    Row("spy --types-jar", ("spy", "--print", "--types-jar", "{IN}"), "jar"),
    Row("realbench", ("realbench", "--format", "msindoor", "{IN}", "--scheduler", "serial", "--out",
        "{OUT}/r.json"), "floor_dir", lab=True),
]  # fmt: skip


@pytest.fixture(scope="module")
def good(tmp_path_factory, stridefixd) -> dict[str, Path]:
    """GIVEN the default SIL walk (two floors) replayed by stridefixd, a site built from it, its analysis, and one good
    file of every other input format."""
    d = tmp_path_factory.mktemp("good")
    assert stridefix_cli.main(["-q", "sim", "--out", str(d)]) == 0
    run = subprocess.run(
        [str(stridefixd), "--input", str(d / "board.candump"), "--log", str(d / "run.lcmlog"), "-q"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    log, truth = str(d / "run.lcmlog"), str(d / "truth.lcmlog")
    site = [
        "radiomap",
        "build",
        log,
        truth,
        "--out",
        str(d / "site.sfsite"),
        "--building",
        str(d / "building.toml"),
    ]
    assert stridefix_cli.main(["-q", *site]) == 0
    assert stridefix_cli.main(["-q", "analyze", log, truth, "--out", str(d / "an")]) == 0
    (d / "trace.txt").write_text(TRACE_TEXT)
    (d / "gsd.txt").write_text(GSD_TEXT)
    (d / "gt.csv").write_text(GT_TEXT)
    (d / "t.est").write_text(EST_TEXT)
    (d / "scenario.toml").write_text("# the defaults\n")
    (d / "floor").mkdir()
    (d / "floor" / "trace.txt").write_text(TRACE_TEXT)
    with zipfile.ZipFile(d / "types.jar", "w") as z:
        z.writestr("META-INF/MANIFEST.MF", "Manifest-Version: 1.0\n")
    (d / "blocker").write_text("a regular file, so nothing can be written below it\n")
    return {
        "lcm": d / "run.lcmlog",
        "trace": d / "trace.txt",
        "gsd": d / "gsd.txt",
        "json": d / "an" / "metrics.json",
        "est": d / "t.est",
        "truth_csv": d / "gt.csv",
        "scenario": d / "scenario.toml",
        "building": d / "building.toml",
        "site": d / "site.sfsite",
        "jar": d / "types.jar",
        "analysis_dir": d / "an",
        "floor_dir": d / "floor",
        "truth": d / "truth.lcmlog",
        "blocker": d / "blocker",
    }


def _hostile_bytes(kind: str, fmt: str, good: dict[str, Path]) -> bytes:
    if kind == "empty":
        return b""
    if kind == "png":
        return b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 16
    if kind == "utf16":
        return UTF16.get(fmt, '{"kind": "x"}\n').encode("utf-16")
    if kind == "junk":
        return random.Random(33).randbytes(4096)
    if kind == "truncated_lcm":
        return good["lcm"].read_bytes()[:40]  # inside the first event's channel name
    assert kind == "huge_numbers", kind
    return HUGE["trace" if fmt == "floor_dir" else "json" if fmt == "analysis_dir" else fmt].encode()


def _hostile(kind: str, fmt: str, where: Path, good: dict[str, Path]) -> Path:
    """The hostile input of ``kind`` for an input of format ``fmt``, below ``where``."""
    path = where / f"hostile-{kind}"
    if kind == "missing":
        return path
    if kind == "directory":
        path.mkdir()
        return path
    data = _hostile_bytes(kind, fmt, good)
    if fmt in FOLDERS:
        path.mkdir()
        names = ("metrics.json", "analysis.npz") if fmt == "analysis_dir" else ("trace.txt",)
        for name in names:
            (path / name).write_bytes(data)
        return path
    path.write_bytes(data)
    return path


def _argv(row: Row, kind: str, where: Path, good: dict[str, Path]) -> tuple[list[str], Path]:
    """The command line of ``row`` with the input of ``kind``, and the path the message must name."""
    out = where / "out"
    named = _hostile(kind, row.fmt, where, good) if kind != "unwritable_out" else good["blocker"]
    if kind == "unwritable_out":
        value, out = good[row.fmt], good["blocker"] / "sub"
    else:
        value = named
    subst = {
        "{IN}": str(value),
        "{OUT}": str(out),
        "{TMP}": str(where),
        "{LOG}": str(good["lcm"]),
        "{TRUTH}": str(good["truth"]),
        "{SITE}": str(good["site"]),
        "{METRICS}": str(good["json"]),
        "{GT}": str(good["truth_csv"]),
        "{EST}": str(good["est"]),
    }
    argv = []
    for arg in row.argv:
        for key, v in subst.items():
            arg = arg.replace(key, v)
        argv.append(arg)
    return argv, named


CASES = [(row, kind) for row in ROWS for kind in (*KINDS, "unwritable_out") if kind != "unwritable_out" or any(
    "{OUT}" in a for a in row.argv)]  # fmt: skip


@pytest.mark.parametrize(("row", "kind"), CASES, ids=[f"{r.name}-{k}" for r, k in CASES])
def test_exit_status_and_one_line_naming_the_file(row, kind, good, tmp_path, capfd):
    argv, named = _argv(row, kind, tmp_path, good)
    main = lab_cli.main if row.lab else stridefix_cli.main
    capfd.readouterr()
    try:
        status = main(["-q", *argv])
    except SystemExit as exc:  # argparse's own usage errors
        status = exc.code if isinstance(exc.code, int) else EXIT_FAILURE
    err = capfd.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err, err
    assert status == row.status(kind), f"{' '.join(argv)}\n{err}"
    if status != EXIT_OK:
        assert len(lines) == 1, f"{' '.join(argv)}\n{err}"
        assert named.name in lines[0], lines[0]


def test_the_table_covers_every_command():
    """A new sub-command gets rows here: every `stridefix` sub-command (and its sub-sub-commands)
    is the first word(s) of some row."""
    covered = {
        " ".join(r.argv[:2]) if r.argv[0] in ("import", "radiomap", "crowd") else r.argv[0] for r in ROWS
    }
    parser = stridefix_cli.build_parser()
    names = set()
    for action in parser._subparsers._group_actions:  # type: ignore[union-attr]
        for name, sub in action.choices.items():
            children = [a for a in sub._actions if a.__class__.__name__ == "_SubParsersAction"]
            names |= {f"{name} {c}" for a in children for c in a.choices} if children else {name}
    assert names - covered == set()


def test_huge_numbers_are_counted_and_skipped_among_good_lines(tmp_path, capfd):
    """A trace whose good lines sit among absurd ones imports (0); the absurd lines are counted."""
    path = tmp_path / "mixed.txt"
    path.write_text(TRACE_TEXT + HUGE["trace"].split("\n", 1)[1])
    out = tmp_path / "mixed.lcmlog"
    assert stridefix_cli.main(["-q", "import", "msindoor", str(path), "-o", str(out)]) == EXIT_OK
    summary = capfd.readouterr().out
    assert '"skipped_lines": 4' in summary, summary
    assert out.stat().st_size > 0
