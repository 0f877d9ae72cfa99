"""Who `stridefix live` answers: its own address only (Host), its own pages only (Origin), whole
requests within a few seconds, and one warning line when it serves beyond this machine.

A web page the user has open must not read the walk: not by opening ``/ws`` from its own origin, not
by renaming 127.0.0.1 under its own host name (DNS rebinding; Chromium's ``--host-resolver-rules``
plays the rebound name here), and a client that never finishes its request must not hold a socket.
"""

from __future__ import annotations

import asyncio
import http.client
import http.server
import json
import random
import re
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from stridefix_analyzer.live.guard import HEADER_TIMEOUT_S, HostCheck

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def _lcm_url() -> str:
    return f"udpm://239.255.76.67:{random.randint(20000, 60000)}?ttl=0"  # this host only, no other run's


def _start(*extra: str) -> tuple[subprocess.Popen, int, str]:
    """`stridefix live` on a free port: the process, its port and its first line of stderr (read once
    the URL line has come, so a warning is already written)."""
    exe = Path(sys.executable).with_name("stridefix")
    proc = subprocess.Popen(
        [str(exe), "live", "--lcm-url", _lcm_url(), "--port", "0", *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = proc.stdout.readline()
    m = re.search(r"http://\S+:(\d+)/", line)
    if not m:
        proc.kill()
        raise AssertionError(line + proc.stderr.read())
    return proc, int(m.group(1)), line


@pytest.fixture
def live():
    proc, port, _ = _start()
    yield port
    proc.terminate()
    proc.wait(timeout=10)


def _get(port: int, path: str, host: str | None, origin: str | None = None) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        conn.putrequest("GET", path, skip_host=True)
        if host is not None:
            conn.putheader("Host", host)
        if origin is not None:
            conn.putheader("Origin", origin)
        conn.endheaders()
        r = conn.getresponse()
        return r.status, r.read()
    finally:
        conn.close()


async def _ws_status(port: int, origin: str | None) -> int:
    """The status of a websocket handshake on /ws sent with ``origin`` (101 when it opened)."""
    import aiohttp

    async with aiohttp.ClientSession() as session:
        try:
            async with session.ws_connect(f"http://127.0.0.1:{port}/ws", origin=origin) as ws:
                msg = await ws.receive(timeout=10)
                assert msg.type == aiohttp.WSMsgType.TEXT and "version" in json.loads(msg.data)
                return 101
        except aiohttp.WSServerHandshakeError as exc:
            return exc.status


def test_websocket_from_another_origin_is_refused(live):
    """GIVEN the live view on 127.0.0.1:PORT, WHEN a websocket handshake carries the Origin of
    another site (or of another port on this machine, or a sandboxed page's "null"), THEN it is
    refused with 403; the server's own origins, and a program that sends none, connect."""
    port = live
    for origin in ("http://evil.example", f"http://evil.example:{port}", "http://127.0.0.1:1", "null"):
        assert asyncio.run(_ws_status(port, origin)) == 403, origin
    for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}", f"http://[::1]:{port}", None):
        assert asyncio.run(_ws_status(port, origin)) == 101, origin


def test_state_for_a_foreign_host_is_refused(live):
    """GIVEN the live view, WHEN /state (or the page) is asked for under a name that is not the
    server's (a rebound name, a wrong port, no Host at all), THEN 421 and no walk; under its own
    names, the snapshot."""
    port = live
    for host in (f"evil.example:{port}", "evil.example", f"127.0.0.1:{port + 1}", "127.0.0.1", None, "x:y"):
        for path in ("/state", "/"):
            status, body = _get(port, path, host)
            # HTTP/1.1 without Host is malformed: aiohttp's parser answers 400 before we are asked
            assert status == (421 if host else 400) and b"walls" not in body, (host, path)
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", f"LOCALHOST:{port}", f"[::1]:{port}"):
        status, body = _get(port, "/state", host)
        assert status == 200 and "walls" in json.loads(body), host
    # a cross-site request carrying another origin is refused too
    assert _get(port, "/state", f"127.0.0.1:{port}", origin="http://evil.example")[0] == 403


def test_unfinished_requests_are_closed_within_the_bound(live):
    """GIVEN the live view, WHEN 200 connections send part of a request line or of the headers and
    then nothing, THEN the server closes every one of them within HEADER_TIMEOUT_S (+2 s), still
    answers a whole request, and keeps an open websocket pushing past that bound."""
    port = live
    partial = [b"GET /state HT", f"GET /state HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n".encode(), b""]
    socks = []
    t0 = time.monotonic()
    for k in range(200):
        s = socket.create_connection(("127.0.0.1", port), timeout=HEADER_TIMEOUT_S + 4)
        s.sendall(partial[k % len(partial)])
        socks.append(s)
    closed_after = []
    for s in socks:
        try:
            data = s.recv(4096)
        except TimeoutError:
            data = None  # still open
        except ConnectionResetError:
            data = b""
        assert data == b"", "a connection with an unfinished request is still open"
        closed_after.append(time.monotonic() - t0)
        s.close()
    assert max(closed_after) < HEADER_TIMEOUT_S + 2
    assert _get(port, "/state", f"127.0.0.1:{port}")[0] == 200

    async def ws_after_the_bound() -> str:
        """What the websocket gets in the bound and 2 s more with nothing to push: nothing, open."""
        import aiohttp

        async with (
            aiohttp.ClientSession() as session,
            session.ws_connect(f"http://127.0.0.1:{port}/ws") as ws,
        ):
            await ws.receive(timeout=10)  # the first document
            try:
                msg = await ws.receive(timeout=HEADER_TIMEOUT_S + 2)
            except asyncio.TimeoutError:
                return "open" if not ws.closed else "closed"
            return str(msg.type)

    assert asyncio.run(ws_after_the_bound()) == "open"


def test_serving_beyond_this_machine_warns():
    """GIVEN --host 0.0.0.0, THEN one warning line says who can then read the walk, and the server
    answers this machine's names and IP literals but still refuses a foreign name; on 127.0.0.1 no
    warning is printed."""
    proc, port, _ = _start("--host", "0.0.0.0")
    try:
        time.sleep(0.3)
        assert _get(port, "/state", f"127.0.0.1:{port}")[0] == 200
        assert _get(port, "/state", f"{socket.gethostname()}:{port}")[0] == 200
        assert _get(port, "/state", f"10.1.2.3:{port}")[0] == 200  # an address: cannot be rebound
        assert _get(port, "/state", f"evil.example:{port}")[0] == 421
    finally:
        proc.terminate()
        _, err = proc.communicate(timeout=10)
    warnings = [ln for ln in err.splitlines() if "warning" in ln]
    assert len(warnings) == 1, err
    assert "anyone who can reach this machine can read the walk" in warnings[0]
    proc, port, _ = _start()
    proc.terminate()
    _, err = proc.communicate(timeout=10)
    assert "warning" not in err


def test_host_check_names():
    c = HostCheck("127.0.0.1", 8765)
    assert c.host_ok("127.0.0.1:8765") and c.host_ok("localhost:8765") and c.host_ok("[::1]:8765")
    assert not c.host_ok("127.0.0.1") and not c.host_ok("10.0.0.1:8765") and not c.host_ok("[::1")
    assert HostCheck("::1", 80).host_ok("[::1]") and HostCheck("192.168.1.5", 81).host_ok("192.168.1.5:81")
    assert c.origin_ok("http://localhost:8765") and not c.origin_ok("https://localhost:8765")
    assert not c.origin_ok("http://localhost:8765/x") and not c.origin_ok("file://")


class _AttackPage(http.server.BaseHTTPRequestHandler):
    """Serves, on another port of this machine (another origin), a page that tries to read the
    walk from the live view: a websocket to its /ws and a fetch of its /state."""

    live_port = 0
    PAGE = """<!DOCTYPE html><html><body><script>
      window.result = {ws: "pending", fetch: "pending"};
      const ws = new WebSocket("ws://127.0.0.1:LIVE/ws");
      ws.onmessage = (ev) => { window.result.ws = "read " + ev.data.length; };
      ws.onerror = () => { if (window.result.ws === "pending") window.result.ws = "refused"; };
      ws.onclose = () => { if (window.result.ws === "pending") window.result.ws = "refused"; };
      fetch("http://127.0.0.1:LIVE/state").then((r) => r.text())
        .then((t) => { window.result.fetch = "read " + t.length; }, () => { window.result.fetch = "refused"; });
    </script></body></html>"""

    def do_GET(self) -> None:  # noqa: N802 (http.server's name)
        body = self.PAGE.replace("LIVE", str(self.live_port)).encode()
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args) -> None:
        pass


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed (tools/deps.sh installs it)")
def test_a_page_of_another_origin_cannot_read_the_walk(live):
    """GIVEN the live view and, in headless Chromium, a page served by another local server (another
    origin) WHEN it opens a websocket to the view and fetches /state, THEN both fail; and WHEN a
    rebound name (evil.example resolved to 127.0.0.1) asks for the page or /state, THEN 421, while
    the view's own page under 127.0.0.1 still connects and goes live."""
    from playwright.sync_api import sync_playwright

    port = live
    handler = type("Attack", (_AttackPage,), {"live_port": port})
    attack = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=attack.serve_forever, daemon=True).start()
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(
                executable_path=CHROMIUM,
                args=["--no-sandbox", "--host-resolver-rules=MAP evil.example 127.0.0.1"],
                headless=True,
            )
            page = browser.new_page()
            page.goto(f"http://127.0.0.1:{attack.server_address[1]}/")
            page.wait_for_function(
                "window.result.ws !== 'pending' && window.result.fetch !== 'pending'", timeout=15000
            )
            page.wait_for_timeout(500)  # a late message would turn "refused" into "read"
            assert page.evaluate("window.result") == {"ws": "refused", "fetch": "refused"}
            for path in ("/", "/state"):
                r = page.goto(f"http://evil.example:{port}{path}")
                assert r is not None and r.status == 421 and "walls" not in page.content(), path
            page.goto(f"http://127.0.0.1:{port}/")
            page.wait_for_function("document.getElementById('status').textContent === 'live'", timeout=15000)
            browser.close()
    finally:
        attack.shutdown()
        attack.server_close()
