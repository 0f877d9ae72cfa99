"""One bad message does not stop `stridefix live`: a POSE cut short is counted and skipped, a POSE
holding NaN or inf is shown as no value (JSON null), and what comes after still arrives.

The messages go through real LCM: multicast that stays on this host (ttl=0, a random port that no
other run shares) into the running server, as the logger would publish them.
"""

from __future__ import annotations

import asyncio
import json
import math
import random
import re
import shutil
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import lcm
import pytest
from stridefix import pose_t

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def _strict(text: str):
    """``text`` as strict JSON: NaN, Infinity and -Infinity are not JSON."""

    def refuse(constant: str):
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def _pose(x_m: float, y_m: float = 0.0, t_us: int = 1_000_000) -> bytes:
    m = pose_t()
    m.t_us, m.x_m, m.y_m, m.scheme = t_us, x_m, y_m, pose_t.SCHEME_ADAPTIVE
    m.heading_rad, m.sigma_m = float("inf"), float("nan")
    return m.encode()


class Live:
    """`stridefix live` on a udpm URL of this host only, and an LCM publisher on the same URL."""

    def __init__(self) -> None:
        self.url = f"udpm://239.255.76.67:{random.randint(20000, 60000)}?ttl=0"
        exe = Path(sys.executable).with_name("stridefix")
        self.proc = subprocess.Popen(
            [str(exe), "live", "--lcm-url", self.url, "--port", "0"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        line = self.proc.stdout.readline()
        m = re.search(r"(http://127\.0\.0\.1:\d+/)", line)
        assert m, line + self.proc.stderr.read()
        self.base = m.group(1)
        self.lc = lcm.LCM(self.url)

    def state_text(self) -> str:
        with urllib.request.urlopen(self.base + "state", timeout=10) as r:
            return r.read().decode()

    def wait(self, pred, timeout_s: float = 10.0) -> dict:
        """The strict-JSON state once ``pred(state)`` holds (fails after ``timeout_s``)."""
        deadline = time.monotonic() + timeout_s
        while True:
            doc = _strict(self.state_text())
            if pred(doc) or time.monotonic() > deadline:
                assert pred(doc), doc
                return doc
            time.sleep(0.05)

    def close(self) -> str:
        self.proc.terminate()
        return self.proc.communicate(timeout=10)[1]


@pytest.fixture
def live():
    v = Live()
    yield v
    v.close()


def _poses(doc: dict) -> int:
    return doc["messages"].get("POSE", 0)


def test_a_truncated_and_a_nan_pose_are_survived(live):
    """GIVEN a websocket client on the view, WHEN a good POSE, a POSE cut to 30 bytes, a POSE with
    NaN x (and inf heading, NaN sigma) and a good POSE again are published, THEN the websocket stays
    open and keeps pushing strict JSON, /state is strict JSON, the cut message is counted (1 bad)
    and skipped, NaN and inf are null, and the last good pose is the one shown."""
    import aiohttp

    async def scenario() -> tuple[list[dict], bool]:
        docs: list[dict] = []
        async with aiohttp.ClientSession() as session, session.ws_connect(live.base + "ws") as ws:
            docs.append(_strict((await ws.receive(timeout=10)).data))
            live.lc.publish("POSE", _pose(1.0))
            await asyncio.to_thread(live.wait, lambda d: _poses(d) == 1)
            live.lc.publish("POSE", _pose(2.0)[:30])
            live.lc.publish("POSE", _pose(float("nan"), 2.0, 2_000_000))
            await asyncio.to_thread(live.wait, lambda d: _poses(d) == 2 and d["bad_messages"] == 1)
            live.lc.publish("POSE", _pose(3.0, 0.0, 3_000_000))
            await asyncio.to_thread(live.wait, lambda d: _poses(d) == 3)
            deadline = time.monotonic() + 5
            while time.monotonic() < deadline and (not docs or _poses(docs[-1]) < 3):
                msg = await ws.receive(timeout=5)
                assert msg.type == aiohttp.WSMsgType.TEXT, msg
                docs.append(_strict(msg.data))
            return docs, ws.closed

    docs, closed = asyncio.run(scenario())
    assert not closed and _poses(docs[-1]) == 3 and docs[-1]["bad_messages"] == 1
    doc = _strict(live.state_text())
    assert doc["bad_messages"] == 1 and _poses(doc) == 3
    (scheme,) = doc["schemes"]
    assert scheme["last"]["x_m"] == 3.0 and scheme["last"]["heading_rad"] is None
    assert scheme["last"]["sigma_m"] is None and doc["primary"]["x_m"] == 3.0
    assert all(all(v is not None and math.isfinite(v) for v in p) for p in scheme["track"])


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed (tools/deps.sh installs it)")
def test_the_page_counts_bad_messages_and_stays_live(live):
    """GIVEN the page in headless Chromium, WHEN a cut POSE and a NaN POSE arrive and then a good
    one, THEN the page says "live", shows 1 bad message and the good pose, with no script error."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
        page = browser.new_page()
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(live.base)
        page.wait_for_function("document.getElementById('status').textContent === 'live'", timeout=15000)
        live.lc.publish("POSE", _pose(2.0)[:30])
        live.lc.publish("POSE", _pose(float("nan"), float("inf"), 2_000_000))
        live.wait(lambda d: _poses(d) == 1 and d["bad_messages"] == 1)
        live.lc.publish("POSE", _pose(4.25, 1.5, 3_000_000))
        live.wait(lambda d: _poses(d) == 2)
        page.wait_for_function(
            "document.querySelector(\"#schemes tr[data-scheme='adaptive'] td:nth-child(3)\")"
            "?.textContent === '4.25'",
            timeout=10000,
        )
        assert page.inner_text("#status") == "live" and page.inner_text("#bad") == "1"
        assert errors == []
        browser.close()
