"""Runs one disk-full episode for test_log_disk_full.py, inside the caller's private mount namespace
(`unshare --mount`): a 2 MB tmpfs on MOUNTPOINT, filled by a filler file up to --free bytes;
stridefixd logs the first half of CANDUMP from stdin into it (the disk fills), the disk stays full
for --hold-s seconds more, the filler is deleted (space returns; never with --never-free), the
second half follows. Prints one JSON object: exit status, stderr (all of it, and what was said
while the disk was full), the files left on the tmpfs, and what the log file holds, read with the
analyzer's reader (the tmpfs vanishes with the namespace).

    python diskfull_run.py STRIDEFIXD CANDUMP MOUNTPOINT [--free BYTES] [--hold-s S] [--never-free]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import threading
import time
from pathlib import Path

from stridefix_analyzer.io.lcmfile import read_file
from stridefix_analyzer.io.logread import read_logs

TMPFS_SIZE = "2m"


def fill(mnt: Path, free_bytes: int) -> Path:
    """A filler file that leaves free_bytes free (0: not one block)."""
    st = os.statvfs(mnt)
    filler = mnt / "filler"
    fd = os.open(filler, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
    try:
        os.write(fd, b"\0" * max(0, st.f_bavail * st.f_frsize - free_bytes))
        while free_bytes == 0:
            os.write(fd, b"\0" * 4096)  # until ENOSPC: not one block left
    except OSError:
        pass
    finally:
        os.close(fd)
    return filler


def log_contents(log: Path) -> dict:
    """What the log holds: events, bytes, the first channel, damage, the last HEALTH."""
    channels: list[str] = []
    info, notes = read_file(str(log), lambda channel, _payload: channels.append(channel))
    health = read_logs([log], decode=["HEALTH"]).health
    return {
        "file_events": len(channels),
        "file_bytes": log.stat().st_size,
        "first_channel": channels[0] if channels else None,
        "truncated_bytes": info["truncated_bytes"],
        "skipped_bytes": info["skipped_bytes"],
        "notes": notes,
        "health": {k: health.get(k) for k in ("log_events", "log_drops", "log_drop_bytes", "frames_total")},
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("stridefixd")
    ap.add_argument("candump", type=Path)
    ap.add_argument("mnt", type=Path)
    ap.add_argument("--free", type=int, default=200_000, help="bytes the filler leaves free")
    ap.add_argument("--hold-s", type=float, default=0.0, help="the disk stays full this long after it failed")
    ap.add_argument("--never-free", action="store_true", help="the filler stays: the disk never has room")
    a = ap.parse_args()
    mnt = a.mnt
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={TMPFS_SIZE}", "tmpfs", str(mnt)], check=True)
    filler = fill(mnt, a.free)
    log = mnt / "full.lcmlog"
    proc = subprocess.Popen(
        [a.stridefixd, "-i", "-", "-l", str(log), "-q"],
        stdin=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdin is not None and proc.stderr is not None
    err_lines: list[str] = []
    reader = threading.Thread(target=lambda: err_lines.extend(proc.stderr), daemon=True)
    reader.start()
    lines = a.candump.read_text().splitlines(keepends=True)
    half = len(lines) // 2
    proc.stdin.writelines(lines[:half])
    proc.stdin.flush()
    end = time.monotonic() + 30
    while not any("writing the log failed" in s for s in err_lines) and time.monotonic() < end:
        time.sleep(0.05)
    full_seen = any("writing the log failed" in s for s in err_lines)
    time.sleep(a.hold_s)
    said_while_full = "".join(err_lines)
    if not a.never_free:
        filler.unlink()
    proc.stdin.writelines(lines[half:])
    proc.stdin.close()
    status = proc.wait(timeout=60)
    reader.join(timeout=10)
    result = {
        "status": status,
        "stderr": "".join(err_lines),
        "stderr_while_full": said_while_full,
        "full_seen": full_seen,
        "files": sorted(p.name for p in mnt.iterdir() if p != filler),
    }
    if log.exists():
        result |= log_contents(log)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
