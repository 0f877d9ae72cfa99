"""stridefixd's exit-status contract and its option/config edge cases.

Each test is a regression of a row of the exit-status table: a PNG as candump was 508 lines, 0 ok, exit 0;
`--config /dev/zero` and `--input /dev/zero` hung; `--config DIR` was accepted; `--set` over 255
characters was cut short silently; `--max-messages abc` was accepted; a config line longer than inih's
limit was split and the error named a later line and a wrong key."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from stridefix_common import exits


def _run(stridefixd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(stridefixd), *args], capture_output=True, text=True, timeout=20)


@pytest.fixture(scope="module")
def png(tmp_path_factory) -> Path:
    """GIVEN binary junk with a PNG signature (lines of it are not candump -L)."""
    path = tmp_path_factory.mktemp("junk") / "photo.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 64 + b"\n" * 10)
    return path


def test_png_as_candump_is_nothing_valid(stridefixd, png):
    proc = _run(stridefixd, "--input", str(png), "--no-log", "-q")
    assert proc.returncode == exits.EXIT_NOTHING_VALID, proc.stderr
    assert f"{png}: nothing valid in the input" in proc.stderr


def test_png_as_lcm_log_is_nothing_valid(stridefixd, png):
    proc = _run(stridefixd, "--replay", str(png), "--no-log")
    assert proc.returncode == exits.EXIT_NOTHING_VALID, proc.stderr
    assert "nothing valid" in proc.stderr


def test_empty_input_is_nothing_valid(stridefixd, tmp_path):
    empty = tmp_path / "empty.candump"
    empty.write_bytes(b"")
    assert _run(stridefixd, "--input", str(empty), "--no-log").returncode == exits.EXIT_NOTHING_VALID
    proc = subprocess.run(
        [str(stridefixd), "--input", "-", "--no-log"], input="", capture_output=True, text=True, timeout=20
    )
    assert proc.returncode == exits.EXIT_NOTHING_VALID


def test_some_valid_lines_among_junk_exit_0(stridefixd, default_walk, png, tmp_path):
    """Bad lines are counted, not fatal: the walk's first 2000 lines after the PNG's bytes."""
    lines = (default_walk["dir"] / "board.candump").read_bytes().splitlines(keepends=True)[:2000]
    mixed = tmp_path / "mixed.candump"
    mixed.write_bytes(png.read_bytes() + b"".join(lines))
    proc = _run(stridefixd, "--input", str(mixed), "--no-log", "-q")
    assert proc.returncode == exits.EXIT_OK, proc.stderr
    assert "bad syntax" in proc.stderr


@pytest.mark.parametrize("option", ["--input", "--config", "--site", "--replay"])
@pytest.mark.parametrize("path", ["/dev/zero", "/tmp"])
def test_devices_and_directories_are_refused(stridefixd, default_walk, option, path):
    walk = str(default_walk["dir"] / "board.candump")
    args = [option, path] if option in ("--input", "--replay") else [option, path, "--input", walk]
    proc = _run(stridefixd, *args, "--no-log", "-q")
    assert proc.returncode == exits.EXIT_USAGE, proc.stderr
    assert f"{path}: " in proc.stderr and "not a file" in proc.stderr


def test_fifo_input_stays_allowed(stridefixd, default_walk, tmp_path):
    """A FIFO is a stream like stdin: it is read, not refused."""
    import os
    import threading

    fifo = tmp_path / "frames.fifo"
    os.mkfifo(fifo)
    lines = (default_walk["dir"] / "board.candump").read_bytes().splitlines(keepends=True)[:500]

    def feed() -> None:
        with open(fifo, "wb") as f:
            f.write(b"".join(lines))

    writer = threading.Thread(target=feed)
    writer.start()
    proc = _run(stridefixd, "--input", str(fifo), "--no-log", "-q")
    writer.join(timeout=20)
    assert proc.returncode == exits.EXIT_OK, proc.stderr


def test_long_set_is_read_whole(stridefixd):
    value = "0.5" + "0" * 300
    proc = _run(stridefixd, "--print-config", "--json", "--set", f"stride.weinberg_k={value}")
    assert proc.returncode == 0, proc.stderr
    row = next(p for p in json.loads(proc.stdout)["params"] if p["key"] == "stride.weinberg_k")
    assert row["value"] == 0.5
    proc = _run(stridefixd, "--print-config", "--set", f"stride.weinberg_k={value}x")
    assert proc.returncode == exits.EXIT_USAGE  # the tail was cut off before, and 0.5 taken
    proc = _run(stridefixd, "--print-config", "--set", "s" * 300 + ".k=1")
    assert proc.returncode == exits.EXIT_USAGE and "characters" in proc.stderr


@pytest.mark.parametrize("value", ["abc", "12x", "", "-1", "99999999999999999999999"])
def test_max_messages_is_parsed_strictly(stridefixd, value):
    proc = _run(stridefixd, "--max-messages", value, "--input", "/nonexistent")
    assert proc.returncode == exits.EXIT_USAGE
    assert "--max-messages" in proc.stderr


def test_path_longer_than_the_buffers_is_refused(stridefixd):
    long_path = "/tmp/" + "d" * 5000 + ".candump"
    for option in ("--input", "--log", "--replay", "--log-dir", "--config"):
        other = [] if option in ("--input", "--replay") else ["--input", "/nonexistent"]
        proc = _run(stridefixd, option, long_path, *other)
        assert proc.returncode == exits.EXIT_USAGE, option
        assert "characters" in proc.stderr, option


def test_print_config_round_trips_as_json(stridefixd, tmp_path):
    """--print-config > all.ini; --config all.ini: the effective parameters are the same, key by key
    (--print-config --json before and after), also with values changed."""
    for sets in ([], ["--set", "stride.weinberg_k=0.55", "--set", "init.floor=-2"]):
        ini = tmp_path / "all.ini"
        ini.write_text(_run(stridefixd, "--print-config", *sets).stdout)
        before = _run(stridefixd, "--print-config", "--json", *sets)
        after = _run(stridefixd, "--config", str(ini), "--print-config", "--json")
        assert after.returncode == 0, after.stderr
        assert json.loads(after.stdout) == json.loads(before.stdout)


def test_over_long_config_line_names_its_own_line(stridefixd, tmp_path):
    ini = tmp_path / "long.ini"
    ini.write_text("[stride]\nweinberg_k = 0.5\n# " + "x" * 300 + "\nweinberg_k = 0.6\n")
    proc = _run(stridefixd, "--config", str(ini), "--print-config")
    assert proc.returncode == exits.EXIT_USAGE
    assert f"{ini}:3: line longer than" in proc.stderr


@pytest.mark.parametrize("option", ["--log", "--log-dir"])
def test_no_log_with_a_log_is_bad_usage(stridefixd, default_walk, tmp_path, option):
    """Regression: `--no-log --log x` silently wrote no log; the two contradict each other, so it is
    bad usage (2) naming both, and nothing runs."""
    walk = str(default_walk["dir"] / "board.candump")
    proc = _run(stridefixd, "--input", walk, "--no-log", option, str(tmp_path / "x"))
    assert proc.returncode == exits.EXIT_USAGE, proc.stderr
    assert proc.stderr.strip() == f"stridefixd: --no-log contradicts {option} (see --help)"
    assert list(tmp_path.iterdir()) == []
