"""Runs one disk-full episode for test_log_disk_full.py, inside the caller's private mount namespace
(`unshare --mount`): a 2 MB tmpfs on MOUNTPOINT, nearly filled by a filler file; stridefixd logs
the first half of CANDUMP from stdin into it (the disk fills), the filler is deleted (space
returns), the second half follows. Prints one JSON object: exit status, stderr, and what the log
file holds, read with the analyzer's reader (the tmpfs vanishes with the namespace).

    python diskfull_run.py STRIDEFIXD CANDUMP MOUNTPOINT
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

from stridefix_analyzer.io.lcmfile import read_file
from stridefix_analyzer.io.logread import read_logs

TMPFS_SIZE = "2m"
FREE_BYTES = 200_000  # left free by the filler: a fraction of the first half's log


def main() -> None:
    stridefixd, candump, mnt = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={TMPFS_SIZE}", "tmpfs", str(mnt)], check=True)
    st = os.statvfs(mnt)
    filler = mnt / "filler"
    filler.write_bytes(b"\0" * (st.f_bavail * st.f_frsize - FREE_BYTES))
    log = mnt / "full.lcmlog"
    proc = subprocess.Popen(
        [stridefixd, "-i", "-", "-l", str(log), "-q"],
        stdin=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    err_lines: list[str] = []
    reader = threading.Thread(target=lambda: err_lines.extend(proc.stderr), daemon=True)
    reader.start()
    lines = candump.read_text().splitlines(keepends=True)
    half = len(lines) // 2
    proc.stdin.writelines(lines[:half])
    proc.stdin.flush()
    end = time.monotonic() + 30
    while not any("writing the log failed" in s for s in err_lines) and time.monotonic() < end:
        time.sleep(0.05)
    full_seen = any("writing the log failed" in s for s in err_lines)
    filler.unlink()
    proc.stdin.writelines(lines[half:])
    proc.stdin.close()
    status = proc.wait(timeout=60)
    reader.join(timeout=10)
    n_events = 0

    def count(_channel: str, _payload: bytes) -> None:
        nonlocal n_events
        n_events += 1

    info, notes = read_file(str(log), count)
    health = read_logs([log], decode=["HEALTH"]).health
    result = {
        "status": status,
        "stderr": "".join(err_lines),
        "full_seen": full_seen,
        "file_events": n_events,
        "file_bytes": log.stat().st_size,
        "truncated_bytes": info["truncated_bytes"],
        "skipped_bytes": info["skipped_bytes"],
        "notes": notes,
        "health": {k: health.get(k) for k in ("log_events", "log_drops", "log_drop_bytes", "frames_total")},
    }
    print(json.dumps(result))


if __name__ == "__main__":
    main()
