"""The log file's lifecycle: NAME.part renamed on a clean close, never an existing
file or a symlink overwritten, unique default names, rotation (size, SIGHUP) with CONFIG heading every
file, SIGTERM/SIGINT as a clean end, the fsync interval honoured after SIGKILL.

GIVEN the default SIL walk's candump, WHEN stridefixd writes it under the condition of each test,
THEN the files on disk are what the summary says. Logs are read back with the analyzer's reader.
"""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest
from stridefix_analyzer.io.lcmfile import read_file
from stridefix_analyzer.io.logread import read_logs


def channels(path: Path) -> list[str]:
    """Every event's channel, in file order, through the analyzer's reader (which must find the file whole)."""
    seen: list[str] = []
    info, notes = read_file(str(path), lambda channel, _payload: seen.append(channel))
    assert (info["truncated_bytes"], info["skipped_bytes"], notes) == (0, 0, []), (path, info, notes)
    return seen


@pytest.fixture(scope="module")
def candump(default_walk) -> Path:
    """GIVEN the default walk's board frames."""
    return default_walk["dir"] / "board.candump"


def run(stridefixd: Path, *args: str, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(stridefixd), *args], capture_output=True, text=True, timeout=120, **kw)


def test_log_is_renamed_from_part_on_clean_close(stridefixd, candump, tmp_path, log_detail):
    log = tmp_path / "walk.lcmlog"
    proc = run(stridefixd, "-i", str(candump), "-l", str(log), "-q")
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk.lcmlog"]
    detail = log_detail(proc.stderr)
    assert (detail["files"], detail["drops"], detail["copies"]) == (1, 0, 0)
    names = channels(log)
    assert len(names) == detail["events"] and log.stat().st_size == detail["bytes"]
    assert names[0] == "CONFIG" and names[-1] == "HEALTH"


def test_existing_log_is_never_overwritten_without_force(stridefixd, candump, tmp_path):
    # Regression: an existing --log was overwritten silently.
    log = tmp_path / "walk.lcmlog"
    log.write_text("precious")
    proc = run(stridefixd, "-i", str(candump), "-l", str(log), "-q")
    assert proc.returncode == 1 and "exists" in proc.stderr and "--force" in proc.stderr
    assert log.read_text() == "precious"
    assert run(stridefixd, "-i", str(candump), "-l", str(log), "-q", "--force").returncode == 0
    assert channels(log)[0] == "CONFIG"


@pytest.mark.parametrize("force", [False, True], ids=["plain", "force"])
def test_symlink_at_the_part_name_is_never_followed(stridefixd, candump, tmp_path, force):
    # Regression: a symlink planted at the predictable name overwrote another file.
    victim = tmp_path / "victim"
    victim.write_text("precious")
    (tmp_path / "walk.lcmlog.part").symlink_to(victim)
    proc = run(
        stridefixd, "-i", str(candump), "-l", str(tmp_path / "walk.lcmlog"), "-q", *(["--force"] * force)
    )
    assert proc.returncode == 1, proc.stderr
    assert victim.read_text() == "precious"
    assert not (tmp_path / "walk.lcmlog").exists()


def test_force_never_truncates_a_hard_link_at_the_part_name(stridefixd, candump, tmp_path):
    # Regression: with --force the .part name was opened with O_TRUNC before its link count was
    # checked, so a hard link planted there had its target emptied, and only then was refused.
    victim = tmp_path / "victim"
    victim.write_text("precious")
    part = tmp_path / "walk.lcmlog.part"
    os.link(victim, part)
    proc = run(stridefixd, "-i", str(candump), "-l", str(tmp_path / "walk.lcmlog"), "-q", "--force")
    assert proc.returncode == 1, proc.stderr
    assert victim.read_text() == "precious"
    assert f"{part}: 2 links" in proc.stderr and "not truncated" in proc.stderr, proc.stderr
    assert not (tmp_path / "walk.lcmlog").exists()


def test_force_reuses_a_part_file_left_by_a_killed_run(stridefixd, candump, tmp_path):
    """A .part of its own (one link, a killed run's) is what --force may start over."""
    part = tmp_path / "walk.lcmlog.part"
    part.write_bytes(b"\0" * 100_000)
    proc = run(stridefixd, "-i", str(candump), "-l", str(tmp_path / "walk.lcmlog"), "-q", "--force")
    assert proc.returncode == 0, proc.stderr
    assert not part.exists() and channels(tmp_path / "walk.lcmlog")[0] == "CONFIG"


def test_two_daemons_started_together_get_different_default_names(stridefixd, candump, tmp_path):
    # Regression: two daemons started in one second shared a file.
    cmd = [str(stridefixd), "-i", str(candump), "-d", str(tmp_path), "-q"]
    procs = [subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True) for _ in range(3)]
    assert all(p.wait(timeout=120) == 0 for p in procs)
    logs = sorted(tmp_path.glob("stridefixd-*.lcmlog"))
    assert len(logs) == 3 and not list(tmp_path.glob("*.part"))
    assert len({channels(p).count("IMU") for p in logs}) == 1  # three whole, equal logs


def test_size_rotation_gives_files_that_each_read_alone(stridefixd, candump, tmp_path, log_detail):
    whole = tmp_path / "whole.lcmlog"
    assert run(stridefixd, "-i", str(candump), "-l", str(whole), "-q").returncode == 0
    rotated = tmp_path / "rot" / "walk.lcmlog"
    rotated.parent.mkdir()
    proc = run(stridefixd, "-i", str(candump), "-l", str(rotated), "-q", "--set", "output.log_rotate_mb=1")
    assert proc.returncode == 0, proc.stderr
    files = sorted(rotated.parent.iterdir())
    detail = log_detail(proc.stderr)
    assert (
        len(files) == detail["files"] >= 5 and files[-1].name == "walk.lcmlog"
    )  # walk.001.lcmlog .. sort first
    assert all(p.stat().st_size <= 1_000_000 for p in files)
    per_file = [channels(p) for p in [files[-1], *files[:-1]]]
    assert all(names[0] == "CONFIG" for names in per_file)
    assert all(read_logs([p], decode=["CONFIG"]).config for p in files)  # each reads alone
    joined = [c for names in per_file for c in names[1:]]
    assert joined == channels(whole)[1:]  # nothing lost, nothing repeated but the CONFIG heads
    assert detail["copies"] == len(files) - 1
    assert sum(map(len, per_file)) == detail["events"]


class Feeder:
    """Feeds candump lines to a running stridefixd's stdin, paced at their own timestamps (real
    time), from a thread; remembers the wall time at which it started."""

    def __init__(self, proc: subprocess.Popen, lines: list[str], pace: bool = True) -> None:
        self.proc, self.lines, self.pace = proc, lines, pace
        self.t0_wall = 0.0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        t0_line = float(self.lines[0].split(")")[0][1:])
        self.t0_wall = time.monotonic()
        try:
            for line in self.lines:
                if self.stop.is_set():
                    break
                if self.pace:
                    delay = self.t0_wall + float(line.split(")")[0][1:]) - t0_line - time.monotonic()
                    if delay > 0:
                        time.sleep(delay)
                self.proc.stdin.write(line)
                self.proc.stdin.flush()
        except (BrokenPipeError, ValueError):
            pass


def start_on_stdin(stridefixd: Path, log: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen(
        [str(stridefixd), "-i", "-", "-l", str(log), "-q", *extra],
        stdin=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for(predicate, timeout_s: float = 20.0) -> None:
    end = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.05)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_stop_signal_closes_the_log_and_exits_0(stridefixd, candump, tmp_path, log_detail, sig):
    # Regression: no handler, so no final flush, no last HEALTH, no summary.
    log = tmp_path / "walk.lcmlog"
    proc = start_on_stdin(stridefixd, log)
    lines = candump.read_text().splitlines(keepends=True)[:3000]
    proc.stdin.writelines(lines)
    proc.stdin.flush()  # stdin stays open: stridefixd is blocked reading it when the signal comes
    part = Path(str(log) + ".part")
    wait_for(lambda: part.exists() and part.stat().st_size > 100_000)
    time.sleep(0.3)
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=10)
    proc.stdin.close()
    assert proc.returncode == 0, stderr
    assert "stopped by signal" in stderr and "3000 frames" in stderr
    assert log.exists() and not part.exists()
    names = channels(log)
    assert names[0] == "CONFIG" and names[-1] == "HEALTH" and len(names) == log_detail(stderr)["events"]
    health = read_logs([log], decode=["HEALTH"]).health
    assert health["frames_total"] == 3000


def test_sighup_rotates_and_the_new_file_starts_with_config(stridefixd, candump, tmp_path, log_detail):
    log = tmp_path / "walk.lcmlog"
    proc = start_on_stdin(stridefixd, log)
    lines = candump.read_text().splitlines(keepends=True)
    proc.stdin.writelines(lines[:2000])
    proc.stdin.flush()
    wait_for(lambda: Path(str(log) + ".part").exists() and Path(str(log) + ".part").stat().st_size > 50_000)
    time.sleep(0.3)
    proc.send_signal(signal.SIGHUP)
    wait_for(log.exists)  # the first file is closed at once, whatever the input does
    proc.stdin.writelines(lines[2000:4000])
    proc.stdin.close()
    stderr = proc.stderr.read()
    proc.wait(timeout=30)
    assert proc.returncode == 0, stderr
    second = tmp_path / "walk.001.lcmlog"
    assert sorted(p.name for p in tmp_path.iterdir()) == [second.name, log.name]
    first_names, second_names = channels(log), channels(second)
    assert first_names[0] == second_names[0] == "CONFIG"
    assert "CONFIG" not in first_names[1:] + second_names[1:]
    detail = log_detail(stderr)
    assert (detail["files"], detail["copies"]) == (2, 1)
    assert len(first_names) + len(second_names) == detail["events"]


def test_sigkill_loses_no_record_older_than_the_fsync_interval(stridefixd, candump, tmp_path):
    """WHEN stridefixd logs a live-paced pipe and is killed with SIGKILL after 3 s, THEN the .part
    holds every record up to output.fsync_interval_ms (1 s) before the kill, and reads whole."""
    interval_s = 1.0
    log = tmp_path / "walk.lcmlog"
    proc = start_on_stdin(stridefixd, log, "--set", f"output.fsync_interval_ms={int(interval_s * 1000)}")
    feeder = Feeder(proc, candump.read_text().splitlines(keepends=True))
    time.sleep(3.0)
    kill_wall = time.monotonic()
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    feeder.stop.set()
    feeder.thread.join(timeout=10)
    part = Path(str(log) + ".part")
    assert part.exists() and not log.exists()
    data = read_logs([part], decode=["IMU"])
    assert data.inputs[0]["truncated_bytes"] == 0
    imu_t_s = data.table("IMU")["t_us"] * 1e-6
    # board time runs at the feed's pace: the first IMU sample was fed about when the feed started
    newest_wall = feeder.t0_wall + (imu_t_s.max() - imu_t_s.min())
    age_s = kill_wall - newest_wall
    assert age_s <= interval_s, f"the newest record in the log is {age_s:.3f} s older than the kill"


def test_time_rotation_closes_files_by_age(stridefixd, candump, tmp_path, log_detail):
    """WHEN output.log_rotate_s=1 and a live-paced feed runs for 2.5 s, THEN at least three files,
    every one but the last renamed while the feed ran, each starting with CONFIG."""
    log = tmp_path / "walk.lcmlog"
    proc = start_on_stdin(stridefixd, log, "--set", "output.log_rotate_s=1")
    feeder = Feeder(proc, candump.read_text().splitlines(keepends=True))
    time.sleep(2.5)
    assert log.exists() and (tmp_path / "walk.001.lcmlog").exists()  # closed by age, not by the stop
    proc.send_signal(signal.SIGTERM)
    stderr = proc.stderr.read()
    proc.wait(timeout=10)
    feeder.stop.set()
    feeder.thread.join(timeout=10)
    assert proc.returncode == 0, stderr
    files = sorted(tmp_path.glob("*.lcmlog"))
    assert len(files) == log_detail(stderr)["files"] >= 3 and not list(tmp_path.glob("*.part"))
    assert all(channels(p)[0] == "CONFIG" for p in files)
