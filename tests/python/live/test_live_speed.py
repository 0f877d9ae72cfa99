"""The live page receives every step of a walk replayed at ``stridefixd --speed 20``.

GIVEN the demo's SIL walk (5.5 minutes, 545 steps) and ``stridefix live`` listening on a multicast LCM URL that stays on this
host (ttl=0, a random port so that no other run on the machine shares it), WHEN a websocket client
holds the page's ``/ws`` open and stridefixd replays the walk at 20x real time publishing to that URL,
THEN the last document the websocket pushed counts as many STEP messages as the log holds (every
step of the walk), and the view has the walk's last step index. Unpaced, the same replay puts the
walk on UDP in a few milliseconds and the receiver drops messages.
"""

from __future__ import annotations

import asyncio
import json
import random
import re
import subprocess
import sys
import time
from pathlib import Path

import lcm
import pytest

SPEED = 20


@pytest.fixture(scope="module")
def walk(tmp_path_factory, cli) -> Path:
    """The demo's walk (tools/demo.sh: `stridefix sim --out DIR`, the default scenario and seed)."""
    out = tmp_path_factory.mktemp("livespeed")
    proc = cli("sim", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    return out


def _start_live(url: str) -> tuple[subprocess.Popen, str]:
    exe = Path(sys.executable).with_name("stridefix")
    proc = subprocess.Popen(
        [str(exe), "live", "--lcm-url", url, "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = proc.stdout.readline()
    m = re.search(r"http://(127\.0\.0\.1:\d+)/", line)
    assert m, line + proc.stderr.read()
    return proc, m.group(1)


async def _watch(host: str, replay: list[str], quiet_s: float) -> tuple[dict, subprocess.CompletedProcess]:
    """Opens /ws, runs the replay, and reads the pushes until the replay has ended and nothing new
    came for quiet_s. The last document and the replay's outcome."""
    import aiohttp

    last: dict = {}
    async with aiohttp.ClientSession() as session, session.ws_connect(f"http://{host}/ws") as ws:
        last = json.loads((await ws.receive(timeout=10)).data)  # the view before the walk
        proc = await asyncio.create_subprocess_exec(
            *replay, stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE
        )
        done = asyncio.ensure_future(proc.communicate())
        while True:
            try:
                msg = await ws.receive(timeout=quiet_s)
            except asyncio.TimeoutError:
                if done.done():
                    break
                continue
            assert msg.type == aiohttp.WSMsgType.TEXT, msg
            last = json.loads(msg.data)
        _, err = await done
    return last, subprocess.CompletedProcess(replay, proc.returncode, "", err.decode())


def test_live_page_receives_every_step_at_speed_20(stridefixd, walk, tmp_path):
    url = f"udpm://239.255.76.67:{random.randint(20000, 60000)}?ttl=0"
    live, host = _start_live(url)
    log = tmp_path / "run.lcmlog"
    replay = [str(stridefixd), "--input", str(walk / "board.candump"), "--log", str(log), "-q"]
    try:
        t0 = time.monotonic()
        doc, proc = asyncio.run(_watch(host, [*replay, "--speed", str(SPEED), "--lcm-url", url], 2.0))
        elapsed = time.monotonic() - t0
    finally:
        live.terminate()
        live.wait(timeout=10)
    assert proc.returncode == 0, proc.stderr
    steps = [e for e in lcm.EventLog(str(log), "r") if e.channel == "STEP"]
    walked_s = json.loads((walk / "sim_summary.json").read_text())["duration_s"]
    assert len(steps) > 400  # the demo's 5.5-minute walk
    assert doc["messages"].get("STEP", 0) == len(steps)
    assert doc["steps"] == len(steps)  # step_t.index of the last step: the first is 1
    assert elapsed >= walked_s / SPEED


@pytest.mark.parametrize(
    ("url", "opened"),
    [
        ("udpm://239.255.76.67:7667?ttl=0", "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304"),
        ("udpm://239.255.76.67:7667", "udpm://239.255.76.67:7667?recv_buf_size=4194304"),
        ("udpm://239.255.76.67:7667?recv_buf_size=65536", "udpm://239.255.76.67:7667?recv_buf_size=65536"),
        ("file:///tmp/run.lcmlog?speed=4", "file:///tmp/run.lcmlog?speed=4"),
        ("memq://", "memq://"),
    ],
)
def test_live_asks_for_a_large_receive_buffer(url, opened):
    from stridefix_analyzer.live.server import receive_url

    assert receive_url(url) == opened
