"""Least privilege: a live bus (socketcan:) is refused as root unless --allow-root;
file replays run as any user.

GIVEN this machine (root, no AF_CAN), WHEN stridefixd is asked for socketcan:vcan0, THEN as root it
refuses before touching the bus (exit 2, naming --allow-root); with --allow-root, or as an
unprivileged user, it goes on to open the bus (and fails for want of AF_CAN or the interface).
"""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest

LIVE = "socketcan:vcan0"

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason="the refusal is of root: run the tests as root")


def run(*cmd: str) -> subprocess.CompletedProcess:
    return subprocess.run(list(cmd), capture_output=True, text=True, timeout=30)


def test_live_input_as_root_is_refused(stridefixd, tmp_path):
    proc = run(str(stridefixd), "-i", LIVE, "-d", str(tmp_path))
    assert proc.returncode == 2
    assert "refusing to read a live bus as root" in proc.stderr and "--allow-root" in proc.stderr
    assert list(tmp_path.iterdir()) == []  # refused before anything was opened


def test_allow_root_goes_on_to_the_bus(stridefixd, tmp_path):
    proc = run(str(stridefixd), "-i", LIVE, "-d", str(tmp_path), "--allow-root")
    assert "refusing" not in proc.stderr
    assert "CAN" in proc.stderr  # no AF_CAN here, or no such interface


def test_unprivileged_user_is_not_refused(stridefixd, tmp_path):
    if shutil.which("setpriv") is None:
        pytest.skip("no setpriv(1) to drop to an unprivileged user")
    tmp_path.chmod(0o777)
    proc = run(
        "setpriv",
        "--reuid=65534",
        "--regid=65534",
        "--clear-groups",
        str(stridefixd),
        "-i",
        LIVE,
        "-d",
        str(tmp_path),
    )
    assert "refusing" not in proc.stderr and "CAN" in proc.stderr, proc.stderr
