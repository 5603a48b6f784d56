"""Who may talk to the viewer's server: the listening socket, and the checks on every
HTTP request, websocket handshake and websocket message before viser sees them.

The page shows the model and lets whoever holds it move the joints, so a web page the
user happens to visit must not reach it:

- **Host header** (DNS rebinding: a page on ``evil.example`` whose name is re-pointed
  at 127.0.0.1 reaches the server with ``Host: evil.example``). A request is answered
  only when its ``Host`` is ``localhost``, ``127.0.0.1``, ``[::1]``, the address it was
  served on or the ``--host`` name, with the server's port (a host named by an allowed
  origin on any port). Anything else gets ``403`` and a short text body.
- **Origin of a websocket handshake** (browsers let any page open a websocket to any
  address and send their page's origin): only the server's own origin
  (``http://HOST:PORT`` with one of the names above) and the origins given with
  ``--allow-origin`` may connect; ``null``, a missing origin, another port or scheme
  get ``403``.
- **Messages** from an accepted page: binary msgpack frames of at most
  :data:`MAX_FRAME_BYTES`, nesting at most :data:`MAX_DEPTH` deep, that viser can read;
  a control update must set the ``value`` of a control of this page to a value of the
  control's kind (a finite number inside a slider's range, a boolean for a checkbox, one
  of a menu's entries). A refused message is dropped before viser applies it.

The listening socket is bound here, once, before viser starts (viser's own loop tries
1000 ports and, when none binds, waits forever for a server that never started).
"""

from __future__ import annotations

import errno
import ipaddress
import math
import re
import socket
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from robotwright.scene.load import ViewError

__all__ = [
    "DEFAULT_PORT",
    "LOCAL_NAMES",
    "MAX_DEPTH",
    "MAX_FRAME_BYTES",
    "PORT_TRIES",
    "Gate",
    "bind_listener",
    "host_key",
    "is_loopback",
    "parse_origin",
]

#: Port tried first when none is given; the next free one up to ``DEFAULT_PORT +
#: PORT_TRIES - 1`` is taken when it is busy. A port given explicitly is that port only.
DEFAULT_PORT = 8080
PORT_TRIES = 100
#: Names under which the server is always reachable from this machine.
LOCAL_NAMES = ("localhost", "127.0.0.1", "[::1]")
#: Largest websocket message accepted from a page (bytes); viser's client sends camera
#: moves and control updates of well under 1 kB.
MAX_FRAME_BYTES = 1 << 20
#: Deepest nesting of lists and maps in a message (viser's messages nest 3 levels).
MAX_DEPTH = 16

_HOST_NAME = re.compile(r"[a-z0-9]([a-z0-9\-._]*[a-z0-9])?\Z")
# A port as browsers write it: no sign, no leading zero (``localhost:08931`` is not
# ``localhost:8931`` to every parser between the page and us).
_PORT = re.compile(r"(0|[1-9][0-9]{0,4})\Z")

#: The messages viser's page sends for what the viewer offers (camera, GUI controls,
#: pointer, clicks, drags, renders, local settings); every other type is refused,
#: among them ShareUrlRequest, file uploads, forms and commands.
PAGE_MESSAGES = frozenset(
    {
        "ViewerCameraMessage",
        "GuiUpdateMessage",
        "GuiButtonHoldMessage",
        "ScenePointerMessage",
        "SceneNodeClickMessage",
        "SceneNodeDragMessage",
        "TransformControlsUpdateMessage",
        "TransformControlsDragStartMessage",
        "TransformControlsDragEndMessage",
        "GetRenderResponseMessage",
        "LocalStorageGetItemResponseMessage",
    }
)


def host_key(host: str) -> str:
    """``host`` as it appears in a URL's authority: lower case, IPv6 in brackets."""
    host = host.strip().lower()
    if ":" in host and not host.startswith("["):
        return f"[{host}]"
    return host


def is_loopback(address: str) -> bool:
    """True when ``address`` (an IP address, bracketed or not) is a loopback address."""
    try:
        return ipaddress.ip_address(address.strip("[]")).is_loopback
    except ValueError:
        return False


def _split_authority(text: str) -> tuple[str, int | None] | None:
    """``host[:port]`` (RFC 3986 authority without user info) as ``(host, port)`` with
    the host lower-cased (IPv6 kept in brackets); None when malformed."""
    text = text.lower()
    if text.startswith("["):
        end = text.find("]")
        if end < 0:
            return None
        host, rest = text[: end + 1], text[end + 1 :]
        try:
            ipaddress.IPv6Address(host[1:-1])
        except ValueError:
            return None
    else:
        host, sep, port_text = text.rpartition(":")
        if not sep:
            host, rest = text, ""
        else:
            rest = ":" + port_text
        if not _HOST_NAME.match(host):
            return None
    if not rest:
        return host, None
    if not rest.startswith(":") or not _PORT.match(rest[1:]):
        return None
    port = int(rest[1:])
    return (host, port) if port <= 65535 else None


@dataclass(frozen=True)
class Origin:
    """A web origin: scheme (``http``/``https``), host (URL form) and port."""

    scheme: str
    host: str
    port: int

    def __str__(self) -> str:
        default = {"http": 80, "https": 443}[self.scheme]
        return f"{self.scheme}://{self.host}" + ("" if self.port == default else f":{self.port}")


def parse_origin(text: str) -> Origin | None:
    """An ``Origin`` header or ``--allow-origin`` value (``scheme://host[:port]``, no
    path) as an :class:`Origin`; None when it is not one (``null``, a path, user info)."""
    if not text.isascii() or not text.isprintable() or text != text.strip():
        return None
    scheme, sep, rest = text.partition("://")
    scheme = scheme.lower()
    if not sep or scheme not in ("http", "https"):
        return None
    rest = rest.removesuffix("/")
    if not rest or any(c in rest for c in "/?#@\\ "):
        return None
    parts = _split_authority(rest)
    if parts is None:
        return None
    host, port = parts
    return Origin(scheme, host, port if port is not None else (80 if scheme == "http" else 443))


def bind_listener(host: str, port: int | None) -> socket.socket:
    """A listening TCP socket on ``host`` (the first address it resolves to) and
    ``port`` (None: :data:`DEFAULT_PORT` or the next free one; 0: any free port).

    Raises:
        ViewError: the name does not resolve, the address is not this machine's, the
            port is taken (a port given explicitly) or needs privileges.
    """
    try:
        infos = socket.getaddrinfo(
            host, None, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE | socket.AI_NUMERICSERV
        )
    except (socket.gaierror, UnicodeError) as exc:
        reason = exc.strerror if isinstance(exc, socket.gaierror) else "not a host name"
        raise ViewError(f"host {host!r}: cannot resolve it ({reason})") from None
    family, _, proto, _, address = infos[0]
    ports = [port] if port is not None else range(DEFAULT_PORT, DEFAULT_PORT + PORT_TRIES)
    last: OSError | None = None
    for candidate in ports:
        sock = socket.socket(family, socket.SOCK_STREAM, proto)
        try:
            # As asyncio does: a restarted viewer may reuse a port still in TIME_WAIT.
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if family == socket.AF_INET6:
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            sock.bind((address[0], candidate, *address[2:]))
            sock.listen(100)
            sock.setblocking(False)
            return sock
        except OSError as exc:
            sock.close()
            last = exc
            if exc.errno != errno.EADDRINUSE:
                break
    assert last is not None
    where = f"{host_key(address[0])}:{port if port is not None else DEFAULT_PORT}"
    if last.errno == errno.EADDRINUSE:
        if port is None:
            hint = f"ports {DEFAULT_PORT}-{DEFAULT_PORT + PORT_TRIES - 1} are all in use"
        else:
            hint = "the port is in use: choose another --port, or 0 for any free port"
    elif last.errno == errno.EADDRNOTAVAIL:
        hint = "the address is not one of this machine's (127.0.0.1 serves this machine)"
    elif last.errno == errno.EACCES:
        hint = "permission denied (ports below 1024 need privileges)"
    else:
        hint = last.strerror or str(last)
    raise ViewError(f"cannot listen on {where}: {hint}")


#: Checks a control update's value; returns why it is refused, or None.
ValueCheck = Callable[[Any], "str | None"]


@dataclass
class Gate:
    """The checks for one server, bound to ``host`` (as given) and ``port`` (bound).

    Attributes:
        host: the ``--host`` value.
        port: the port the server listens on.
        allowed_origins: origins other than the server's own that may connect.
        refused: called with a one-line reason for every refused request or message.
    """

    host: str
    port: int
    allowed_origins: tuple[Origin, ...] = ()
    refused: Callable[[str], None] = field(default=lambda _reason: None)

    def _names(self, local_address: str | None) -> set[str]:
        names = set(LOCAL_NAMES) | {host_key(self.host)}
        if local_address:
            names.add(host_key(local_address))
        return names

    def check_host(self, values: list[str], local_address: str | None) -> str | None:
        """Why a request with these ``Host`` header values is refused, or None."""
        if len(values) != 1:
            return f"expected one Host header, got {len(values)}"
        parts = _split_authority(values[0].strip())
        if parts is None:
            return "malformed Host header"
        host, port = parts
        if host in {o.host for o in self.allowed_origins}:
            return None
        port = 80 if port is None else port
        if host in self._names(local_address) and port == self.port:
            return None
        return "Host header names another server (DNS rebinding?)"

    def check_origin(self, values: list[str], local_address: str | None) -> str | None:
        """Why a websocket handshake with these ``Origin`` header values is refused."""
        if len(values) != 1:
            return f"expected one Origin header, got {len(values)}"
        origin = parse_origin(values[0])
        if origin is None:
            return "Origin is not a web page's origin"
        if origin in self.allowed_origins:
            return None
        own = origin.scheme == "http" and origin.port == self.port
        if own and origin.host in self._names(local_address):
            return None
        return f"Origin {origin} may not connect (allow it with --allow-origin)"

    def check_request(self, headers: Any, local_address: str | None) -> str | None:
        """Why an HTTP request (page file or websocket handshake) is refused, or None.

        ``headers`` is a ``websockets`` header map (``get_all``)."""
        reason = self.check_host(headers.get_all("Host"), local_address)
        if reason is None and _is_upgrade(headers):
            reason = self.check_origin(headers.get_all("Origin"), local_address)
        return reason


def _is_upgrade(headers: Any) -> bool:
    """A websocket handshake (or anything that asks to be one)."""
    return bool(headers.get_all("Upgrade") or headers.get_all("Sec-WebSocket-Key"))


def depth_of(value: Any, limit: int) -> int:
    """Nesting depth of lists/tuples/dicts in ``value``, counted up to ``limit + 1``."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, (list, tuple, dict)):
            deepest = max(deepest, depth)
            if deepest > limit:
                return deepest
            children: Iterable[Any] = item.values() if isinstance(item, dict) else item
            stack.extend((child, depth + 1) for child in children)
    return deepest


def check_frame(raw: object, deserialize: Callable[[bytes], Any]) -> tuple[Any, str | None]:
    """Decode one websocket message from a page: ``(message, None)``, or ``(None,
    reason)`` when it is not a binary msgpack frame within the limits that viser reads
    (``deserialize``: viser's ``Message.deserialize``)."""
    import msgspec

    if not isinstance(raw, bytes):
        return None, "text frame (the page sends binary msgpack)"
    if len(raw) > MAX_FRAME_BYTES:
        return None, f"message of {len(raw)} bytes (at most {MAX_FRAME_BYTES})"
    try:
        mapping = msgspec.msgpack.decode(raw)
    except (msgspec.DecodeError, RecursionError, ValueError) as exc:
        return None, f"not msgpack ({type(exc).__name__})"
    if depth_of(mapping, MAX_DEPTH) > MAX_DEPTH:
        return None, f"nested deeper than {MAX_DEPTH} levels"
    if not isinstance(mapping, dict) or not isinstance(mapping.get("type"), str):
        return None, "not a message (a map with a 'type')"
    if mapping["type"] not in PAGE_MESSAGES:
        # A share-URL request makes viser dial its public relay from a forked copy;
        # uploads, forms and commands are features the viewer's page does not offer.
        return None, f"{mapping['type'][:60]!r}: not a message the viewer's page sends"
    try:
        return deserialize(raw), None
    except Exception as exc:  # viser's reader fails in many ways on foreign input
        return None, f"{mapping['type'][:60]!r}: not a message viser reads ({type(exc).__name__})"


def check_value(current: Any, value: Any, lo: Any = None, hi: Any = None) -> str | None:
    """Why ``value`` cannot replace a control's ``current`` value, or None: the same kind
    (a boolean for a boolean, a finite number for a number, text for text, a tuple of as
    many such items for a tuple) and, for numbers, inside ``[lo, hi]`` when given."""
    if isinstance(current, bool):
        return None if isinstance(value, bool) else f"expected true or false, got {_show(value)}"
    if isinstance(current, (int, float)):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"expected a number, got {_show(value)}"
        if not math.isfinite(value):
            return f"expected a finite number, got {value}"
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            return f"{value:g} is outside [{_num(lo)}, {_num(hi)}]"
        return None
    if isinstance(current, str):
        return None if isinstance(value, str) else f"expected text, got {_show(value)}"
    if isinstance(current, tuple):
        if not isinstance(value, (list, tuple)) or len(value) != len(current):
            return f"expected {len(current)} values, got {_show(value)}"
        for i, (c, v) in enumerate(zip(current, value, strict=True)):
            reason = check_value(
                c,
                v,
                lo[i] if isinstance(lo, tuple) else lo,
                hi[i] if isinstance(hi, tuple) else hi,
            )
            if reason:
                return f"item {i}: {reason}"
        return None
    return f"this control takes no value from the page (got {_show(value)})"


def _num(x: Any) -> str:
    return "..." if x is None else f"{x:g}"


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
