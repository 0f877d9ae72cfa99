"""Regression: `stridefix import gsd` of an empty, random or UTF-16 file said "1/1
imported", wrote an empty log and exited 0; `import msindoor` of a header-only file the same.

GIVEN a file without one valid sensor record, WHEN it is imported, THEN a NothingValidError names the
file (and the first malformed line, and why it is not text where it can tell), nothing is written,
and the command exits EXIT_NOTHING_VALID; a file with some valid records among bad ones still
imports and exits 0."""

from __future__ import annotations

import argparse
import os

import pytest
from stridefix_analyzer.datasets import cli as import_cli
from stridefix_analyzer.datasets import gsd, msindoor
from stridefix_analyzer.datasets.lcmwrite import write_lcmlog
from stridefix_analyzer.datasets.protocol import NothingValidError
from stridefix_common import exits


def _run_import(*argv: str) -> int:
    """`stridefix import ...` in-process (the console script costs seconds per start)."""
    parser = argparse.ArgumentParser(prog="stridefix")
    import_cli.add_parser(parser.add_subparsers(dest="command"))
    return import_cli.run(parser.parse_args(["import", *argv]))


GSD_TEXT = "% GetSensorData\nACCE;1.0;2.0;0.1;0.2;9.8;3\nPOSI;1.0;1;49.46;11.11;0;100\n"

JUNK = {
    "empty": (b"", "the file is empty"),
    "random": (bytes(range(256)) * 8, "NUL bytes"),
    "utf16": (GSD_TEXT.encode("utf-16"), "UTF-16 (little-endian) byte-order mark"),
}


@pytest.mark.parametrize("kind", sorted(JUNK))
def test_gsd_of_junk_exits_nothing_valid_and_writes_nothing(kind, tmp_path, capsys):
    data, why = JUNK[kind]
    path = tmp_path / f"{kind}.txt"
    path.write_bytes(data)
    out = tmp_path / "out.lcmlog"
    assert _run_import("gsd", str(path), "-o", str(out)) == exits.EXIT_NOTHING_VALID
    err = capsys.readouterr().err
    assert f"{path}: nothing valid in the input" in err
    assert why in err
    assert "0/1 logfile(s) imported" in err
    assert not out.exists() and not os.path.exists(f"{out}.part")


def test_gsd_error_names_the_first_malformed_line(tmp_path):
    path = tmp_path / "tags.txt"
    path.write_text("% header\nACCE;x;2.0;0.1;0.2;9.8;3\nGYRO;1;2\n", encoding="utf-8")
    with pytest.warns(), pytest.raises(NothingValidError) as exc:
        gsd.DATASET.import_walk(path, tmp_path / "out.lcmlog")
    assert exc.value.path == str(path)
    assert "2 malformed (the first: line 2," in str(exc.value)
    assert not (tmp_path / "out.lcmlog").exists()


def test_msindoor_header_only_exits_nothing_valid(tmp_path, capsys):
    path = tmp_path / "header.txt"
    path.write_text("#\tstartTime:1000\n#\tSiteID:x\tFloorName:B1\n#\tendTime:9000\n", encoding="utf-8")
    out = tmp_path / "logs"
    assert _run_import("msindoor", str(path), "--out", str(out)) == exits.EXIT_NOTHING_VALID
    assert f"{path}: nothing valid in the input" in capsys.readouterr().err
    assert not (out / "header.lcmlog").exists()


def test_some_valid_records_still_import(handmade_trace, tmp_path):
    """The handmade trace has four malformed lines among its records: imported, exit 0."""
    assert _run_import("msindoor", str(handmade_trace), "-o", str(tmp_path / "t.lcmlog")) == exits.EXIT_OK
    assert (tmp_path / "t.lcmlog").stat().st_size > 0


def test_one_empty_input_among_good_ones_is_not_ok(gsd_log, tmp_path):
    empty = tmp_path / "empty.txt"
    empty.write_bytes(b"")
    status = _run_import("gsd", str(gsd_log), str(empty), "--out", str(tmp_path / "logs"))
    assert status == exits.EXIT_NOTHING_VALID
    assert (tmp_path / "logs" / "handmade_gsd.lcmlog").is_file()


def test_a_failed_write_leaves_no_partial_log(tmp_path, monkeypatch):
    """The log is written as NAME.part and renamed when whole; a failure midway removes the part and
    leaves an existing NAME as it was."""
    walk = msindoor.DATASET.read(_write_one_sample_trace(tmp_path))
    out = tmp_path / "walk.lcmlog"
    out.write_bytes(b"old")

    def fail(_src: object, _dst: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError):
        write_lcmlog(walk, out)
    assert out.read_bytes() == b"old"
    assert not os.path.exists(f"{out}.part")
    monkeypatch.undo()
    assert write_lcmlog(walk, out) == 1


def _write_one_sample_trace(tmp_path):
    path = tmp_path / "one.txt"
    path.write_text("#\tFloorName:F1\n1000\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n", encoding="utf-8")
    return path
