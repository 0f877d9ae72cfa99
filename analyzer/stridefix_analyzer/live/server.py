"""``stridefix live --lcm-url URL``: serve the live view on 127.0.0.1 (aiohttp: the page and a websocket).

An LCM thread subscribes to what the page draws (POSE and the per-scheme POSE_* channels, STEP, FIX,
HEALTH, CONTEXT, TRUTH), decodes each message with its generated type (the channel table,
lcmtypes/channels.csv) and folds it into a :class:`~.state.LiveState` under a lock. The page (``/``,
:mod:`.page`) opens ``/ws``; every :data:`PUSH_S` the server sends what changed since its last
message to that client (new track points only). ``/state`` answers the whole snapshot as JSON (for
scripts and tests). A ``file://`` URL replays a log (``file:///path/run.lcmlog?speed=1``, LCM's log
provider): the page then says when the log has ended. Nothing is fetched from outside: the page has
no external scripts, fonts or images.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import socket
import sys
import threading
from typing import Any

from stridefix_analyzer.io.channels import POSE_CHANNELS
from stridefix_analyzer.live.guard import HEADER_TIMEOUT_S, HostCheck, exposure_warning, middleware, url_host
from stridefix_analyzer.live.state import LiveState, to_json

PUSH_S = 0.2
DEFAULT_PORT = 8765
#: the channels the view folds, from the channel table (a regular expression, as LCM subscribes)
SUBSCRIBE = "|".join(sorted(POSE_CHANNELS | {"STEP", "FIX", "HEALTH", "CONTEXT", "TRUTH"}))


class LiveInputError(ValueError):
    """The LCM URL or the site cannot be used (the message says which and why)."""


#: the kernel receive buffer asked for on a udpm:// URL that names none [bytes] (capped by the kernel's
#: net.core.rmem_max): a replay at ``stridefixd --speed 20`` sends ~4,000 datagrams a second, which the
#: default buffer (~200 of them) holds for 50 ms of a stalled Python thread; this holds about a second
RECV_BUF_BYTES = 4 * 1024 * 1024


def receive_url(lcm_url: str) -> str:
    """``lcm_url`` with ``recv_buf_size`` = :data:`RECV_BUF_BYTES` added when it is a udpm:// URL
    without one (any other URL, or one that names its own, as it is)."""
    if not lcm_url.startswith("udpm://") or "recv_buf_size=" in lcm_url:
        return lcm_url
    return f"{lcm_url}{'&' if '?' in lcm_url else '?'}recv_buf_size={RECV_BUF_BYTES}"


class LcmFeed:
    """The LCM thread: ``lcm_url`` folded into ``state`` until :meth:`stop` or the log's end."""

    def __init__(self, lcm_url: str, state: LiveState, lock: threading.Lock) -> None:
        import lcm

        try:
            self.lc = lcm.LCM(receive_url(lcm_url))
        except (OSError, RuntimeError, ValueError) as exc:
            raise LiveInputError(f"--lcm-url {lcm_url}: cannot open LCM: {exc}") from exc
        self.state, self.lock = state, lock
        self._stop = threading.Event()
        self.lc.subscribe(SUBSCRIBE, self._on_message)
        self.thread = threading.Thread(target=self._run, name="lcm-feed", daemon=True)

    def _on_message(self, channel: str, data: bytes) -> None:
        with self.lock:
            self.state.fold(channel, data)  # a bad message is counted and skipped

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self.lc.handle_timeout(100)
            except OSError:  # LCM's log provider at the end of a file:// log
                break
        with self.lock:
            self.state.ended = True

    def start(self) -> None:
        self.thread.start()

    def stop(self) -> None:
        self._stop.set()
        self.thread.join(timeout=2)


def make_app(state: LiveState, lock: threading.Lock, check: HostCheck) -> Any:
    """The aiohttp application: ``/`` the page, ``/state`` the snapshot, ``/ws`` the pushes; only
    for the names and origins ``check`` allows (:mod:`.guard`)."""
    from aiohttp import WSMsgType, web

    from stridefix_analyzer.live.page import PAGE

    async def page(_request: web.Request) -> web.Response:
        return web.Response(text=PAGE, content_type="text/html")

    async def snapshot(_request: web.Request) -> web.Response:
        with lock:
            doc = state.snapshot()
        return web.json_response(doc, dumps=to_json)

    async def ws(request: web.Request) -> web.WebSocketResponse:
        sock = web.WebSocketResponse(heartbeat=10)
        await sock.prepare(request)
        sent: dict[int, tuple[int, int]] = {}
        version = -1
        reader = asyncio.ensure_future(sock.receive())
        try:
            while not sock.closed:
                with lock:
                    doc = state.snapshot(sent) if state.version != version or state.ended else None
                    version = state.version
                if doc is not None:
                    await sock.send_str(to_json(doc))
                done, _ = await asyncio.wait({reader}, timeout=PUSH_S)
                if done:
                    msg = reader.result()
                    if msg.type in (WSMsgType.CLOSE, WSMsgType.CLOSED, WSMsgType.ERROR):
                        break
                    reader = asyncio.ensure_future(sock.receive())
        finally:
            reader.cancel()
        return sock

    async def no_icon(_request: web.Request) -> web.Response:
        return web.Response(status=204)  # no icon, and no 404 in the browser's console

    app = web.Application(middlewares=[middleware(check)])
    app.add_routes(
        [
            web.get("/", page),
            web.get("/state", snapshot),
            web.get("/ws", ws),
            web.get("/favicon.ico", no_icon),
        ]
    )
    return app


def plan_of(
    site_path: str | None,
) -> tuple[list[tuple[float, float, float, float, int]], list[dict[str, Any]]]:
    """The site's floor plan: its walls [(x0, y0, x1, y1, floor)] and ports [{kind (building.toml's
    name), x_m, y_m, radius_m, floor_lo, floor_hi}]; none without a site."""
    if not site_path:
        return [], []
    from stridefix_analyzer.io.sitefile import SiteFileError, read_site
    from stridefix_analyzer.scoring.walls import PORT_KINDS

    try:
        s = read_site(site_path)
    except SiteFileError as exc:
        raise LiveInputError(str(exc)) from exc
    walls = [
        (float(a), float(b), float(c), float(d), int(f))
        for a, b, c, d, f in zip(s.wall_x0_m, s.wall_y0_m, s.wall_x1_m, s.wall_y1_m, s.wall_floor)
    ]
    ports = [
        {
            "kind": PORT_KINDS.get(int(k), f"kind_{int(k)}"),
            "x_m": float(x),
            "y_m": float(y),
            "radius_m": float(r),
            "floor_lo": int(lo),
            "floor_hi": int(hi),
        }
        for k, x, y, r, lo, hi in zip(
            s.port_kind, s.port_x_m, s.port_y_m, s.port_radius_m, s.port_floor_lo, s.port_floor_hi
        )
    ]
    return walls, ports


def walls_of(site_path: str | None) -> list[tuple[float, float, float, float, int]]:
    """The site's walls [(x0, y0, x1, y1, floor)], none without a site."""
    return plan_of(site_path)[0]


async def serve(lcm_url: str, site: str | None, host: str, port: int, ready: Any = None) -> None:
    """Run the view until cancelled; ``ready(url)`` is called once it listens."""
    from aiohttp import web

    walls, ports = plan_of(site)
    state, lock = LiveState(walls, source=lcm_url, ports=ports), threading.Lock()
    feed = LcmFeed(lcm_url, state, lock)
    # our own socket: with port 0 the kernel picks a free port, and we can say which (and allow it)
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError as exc:
        sock.close()
        raise LiveInputError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from exc
    bound = sock.getsockname()[1]
    # keepalive_timeout bounds a connection's wait for a whole request from its start (guard.py)
    runner = web.AppRunner(
        make_app(state, lock, HostCheck(host, bound)), access_log=None, keepalive_timeout=HEADER_TIMEOUT_S
    )
    await runner.setup()
    try:
        await web.SockSite(runner, sock).start()
        feed.start()
        warning = exposure_warning(host, bound)
        if warning:
            print(warning, file=sys.stderr, flush=True)
        if ready is not None:
            ready(f"http://{url_host(host)}:{bound}/")
        await asyncio.Event().wait()  # until cancelled (Ctrl-C)
    finally:
        feed.stop()
        await runner.cleanup()


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "live",
        help="a live view of a walk in the browser: every scheme on the floor plan, floor, steps, fixes, health",
        description="Subscribe to the logger's LCM messages and serve a page that draws the walk as it "
        "happens. A file:// URL replays a log: file:///path/run.lcmlog?speed=1.",
    )
    p.add_argument(
        "--lcm-url", required=True, metavar="URL", help="LCM URL to listen on (udpm://…, file://…)"
    )
    p.add_argument(
        "--site",
        metavar="FILE",
        help="site file whose walls and ports (doors, stairs, elevators) are the floor plan",
    )
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to serve on (default: 127.0.0.1, this machine only; any other "
        "address lets whoever reaches it read the walk: a warning says so)",
    )
    p.add_argument(
        "--port",
        type=int,
        default=DEFAULT_PORT,
        help=f"port to serve on, 0 = any free one (default: {DEFAULT_PORT})",
    )
    return p


def run(args: argparse.Namespace) -> int:
    def ready(url: str) -> None:
        print(f"stridefix live: {args.lcm_url} -> {url} (Ctrl-C to stop)", flush=True)

    try:
        with contextlib.suppress(KeyboardInterrupt):
            asyncio.run(serve(args.lcm_url, args.site, args.host, args.port, ready))
    except LiveInputError as exc:
        print(f"stridefix live: error: {exc}", file=sys.stderr)
        return 2
    return 0
