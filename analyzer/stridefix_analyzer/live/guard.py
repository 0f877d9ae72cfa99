"""Who the live view answers: the names it serves under, the web pages that may open its websocket,
and how long a connection may take to send its request.

A browser lets any page it shows open a websocket to any address and send requests to any name, and
a name the page's own server controls can be made to resolve to 127.0.0.1 (DNS rebinding). The walk
on ``/state`` and ``/ws`` (positions, floor, steps, fixes) is therefore answered only:

- for a ``Host`` header that names this server: ``127.0.0.1``, ``localhost`` or ``[::1]`` with the
  port served, or the ``--host`` given; when serving on every interface (``0.0.0.0``, ``::``) also
  this machine's host name and any IP address literal (a literal cannot be rebound). Anything else,
  a missing ``Host`` included, is answered 421 (Misdirected Request);
- for a request carrying an ``Origin`` (browsers send one with every websocket and cross-site
  request) only when that origin is ``http://`` + one of those names: any other page gets 403.
  A request without ``Origin`` comes from a program, not from a page, and is answered.

A connection that has not sent a whole request within :data:`HEADER_TIMEOUT_S` is closed (aiohttp's
``keepalive_timeout``, which bounds a connection's wait for its next request from the moment it is
accepted), so unfinished requests cannot hold the server's sockets.
"""

from __future__ import annotations

import ipaddress
import socket
import urllib.parse
from typing import Any

#: how long a connection may take to send a whole request, and may stay idle between requests [s]
HEADER_TIMEOUT_S = 5.0
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")
WILDCARD_HOSTS = ("0.0.0.0", "::", "")


def _bracket(host: str) -> str:
    """``host`` as it stands in a URL or a Host header (an IPv6 address in brackets)."""
    return f"[{host}]" if ":" in host and not host.startswith("[") else host


def is_loopback(host: str) -> bool:
    """Whether serving on ``host`` reaches this machine only."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def url_host(host: str) -> str:
    """The name to print in the server's URL: 127.0.0.1 for a wildcard address (it is served too)."""
    return "127.0.0.1" if host in WILDCARD_HOSTS else _bracket(host)


class HostCheck:
    """The Host values and origins the server at ``host``:``port`` answers (module docstring)."""

    def __init__(self, host: str, port: int) -> None:
        names = {*LOOPBACK_NAMES, _bracket(host).lower()}
        self.wildcard = host in WILDCARD_HOSTS
        if self.wildcard:
            names |= {socket.gethostname().lower(), socket.getfqdn().lower()}
        self.port = port
        self.names = frozenset(n for n in names if n)

    def host_ok(self, value: str | None) -> bool:
        """Whether a ``Host`` header value (``name:port``; ``name`` alone for port 80) names us."""
        if not value:
            return False
        try:
            parts = urllib.parse.urlsplit(f"//{value}")
            name, port = parts.hostname, parts.port
        except ValueError:  # a port that is not a number, an unbalanced bracket
            return False
        if name is None or (port if port is not None else 80) != self.port:
            return False
        if _bracket(name) in self.names:
            return True
        if not self.wildcard:
            return False
        try:
            ipaddress.ip_address(name)
        except ValueError:
            return False
        return True

    def origin_ok(self, origin: str) -> bool:
        """Whether a page of ``origin`` (``scheme://host[:port]``) is one this server served."""
        try:
            parts = urllib.parse.urlsplit(origin)
        except ValueError:
            return False
        return parts.scheme == "http" and not parts.path and self.host_ok(parts.netloc)


def middleware(check: HostCheck) -> Any:
    """An aiohttp middleware answering 421 to a foreign ``Host`` and 403 to a foreign ``Origin``."""
    from aiohttp import web

    @web.middleware
    async def guard(request: web.Request, handler: Any) -> web.StreamResponse:
        if not check.host_ok(request.headers.get("Host")):
            return web.Response(status=421, text="stridefix live answers to its own address only\n")
        origin = request.headers.get("Origin")
        if origin is not None and not check.origin_ok(origin):
            return web.Response(status=403, text="stridefix live: pages of other sites may not connect\n")
        return await handler(request)

    return guard


def exposure_warning(host: str, port: int) -> str | None:
    """The warning line for serving beyond this machine (``None`` on a loopback address)."""
    if is_loopback(host):
        return None
    where = "every network interface" if host in WILDCARD_HOSTS else host
    return (
        f"stridefix live: warning: serving on {where} port {port}: anyone who can reach this machine "
        "can read the walk (positions, floor, steps, fixes); there is no login or encryption"
    )
