"""Start viser's server on our listening socket, with the gate in front of it.

viser opens its websocket server itself (``websockets.asyncio.server.serve`` with its
own host, port and request handler) and offers no hook for either. While a
:class:`~robotwright.view.server.Viewer` creates its ``ViserServer``, viser's module
sees a ``serve`` that (1) listens on the socket :func:`~robotwright.view.gate.
bind_listener` already bound, (2) answers a request only after the gate's Host and
Origin checks, (3) caps a message at :data:`~robotwright.view.gate.MAX_FRAME_BYTES` and
(4) hands viser only the messages the gate lets through. The swap is undone as soon as
the server runs; a viser that no longer opens its server this way is refused (the
caller sees that ``serve`` was never called) rather than run without the gate.
"""

from __future__ import annotations

import contextlib
import http
import threading
from collections.abc import Callable, Iterator
from typing import Any

from robotwright.view.gate import MAX_FRAME_BYTES, Gate, check_frame

#: One server is created at a time: the swap is of a module attribute of viser's.
_SWAP_LOCK = threading.Lock()


class _Namespace:
    """A stand-in for a module: the given attributes, every other one the module's."""

    def __init__(self, module: Any, **replaced: Any) -> None:
        self._module = module
        self.__dict__.update(replaced)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._module, name)


@contextlib.contextmanager
def gated_viser(
    listener: Any,
    gate: Gate,
    check_message: Callable[[Any], str | None],
    refuse_message: Callable[[Any, str], None],
) -> Iterator[Callable[[], bool]]:
    """Within this block a new ``viser.ViserServer`` serves on ``listener`` through
    ``gate``; yields a function telling whether it did.

    Args:
        listener: the bound, listening socket.
        gate: Host/Origin checks (``gate.refused`` is told each refused request).
        check_message: why a decoded viser message is refused, or None.
        refuse_message: called with the connection and the reason of each refused one.
    """
    import websockets
    import websockets.asyncio.server as ws_server
    from viser import _messages
    from viser.infra import _infra

    deserialize = _messages.Message.deserialize
    calls: list[int] = []

    class GatedConnection(ws_server.ServerConnection):
        """A connection whose ``recv`` returns only the messages the gate lets through."""

        async def recv(self, decode: bool | None = None) -> Any:  # type: ignore[override]
            while True:
                raw = await super().recv(decode)
                message, reason = check_frame(raw, deserialize)
                if reason is None:
                    reason = check_message(message)
                if reason is None:
                    return raw
                refuse_message(self, reason)

    def gated_request(inner: Callable[..., Any] | None) -> Callable[..., Any]:
        def process_request(connection: Any, request: Any) -> Any:
            local = connection.local_address[0] if connection.local_address else None
            reason = gate.check_request(request.headers, local)
            if reason is not None:
                gate.refused(f"request for {request.path[:80]!r}: {reason}")
                return connection.respond(http.HTTPStatus.FORBIDDEN, f"forbidden: {reason}\n")
            return inner(connection, request) if inner is not None else None

        return process_request

    def serve(handler: Any, host: Any = None, port: Any = None, **kwargs: Any) -> Any:
        calls.append(1)
        kwargs.pop("origins", None)  # the gate checks origins
        kwargs["process_request"] = gated_request(kwargs.get("process_request"))
        kwargs["max_size"] = MAX_FRAME_BYTES
        kwargs["create_connection"] = GatedConnection
        return ws_server.serve(handler, sock=listener, **kwargs)

    stand_in = _Namespace(
        websockets,
        asyncio=_Namespace(websockets.asyncio, server=_Namespace(ws_server, serve=serve)),
    )
    with _SWAP_LOCK:
        real = _infra.websockets
        _infra.websockets = stand_in
        try:
            yield lambda: bool(calls)
        finally:
            _infra.websockets = real
