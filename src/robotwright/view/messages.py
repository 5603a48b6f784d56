"""Messages from the page, checked before viser acts on them: a value a slider cannot
have, an unknown node or a malformed message is refused and counted (a part of
:class:`~robotwright.view.server.Viewer`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from robotwright.view.gate import check_value

if TYPE_CHECKING:
    pass


class PageMessages:
    """Checking and refusing the page's messages; a base of
    :class:`~robotwright.view.server.Viewer`, whose ``__init__`` sets the attributes used here."""

    # -- messages from the page ----------------------------------------------------------
    def _check_message(self, message: Any) -> str | None:
        """Why a message from the page is refused, or None: a control update must set
        the value of one of this page's controls to a value of its kind (a slider's: a
        finite number inside its range; a menu's: one of its entries)."""
        if type(message).__name__ != "GuiUpdateMessage":
            return None
        handles = self.server.gui._gui_input_handle_from_uuid
        handle = handles.get(message.uuid) if isinstance(message.uuid, str) else None
        if handle is None:
            return "update of a control this page does not have"
        updates = message.updates
        if not isinstance(updates, dict) or set(updates) != {"value"}:
            return "a control update may set its value only"
        value = updates["value"]
        j = self._slider_joint.get(message.uuid)
        a = self._slider_actuator.get(message.uuid)
        if j is not None:
            label = f"joint '{self._joint_label(j)}'"
        elif a is not None:
            label = f"actuator '{self._actuator_label(a)}'"
        else:
            label = f"control {handle.label!r}"
        if getattr(handle, "disabled", False):
            return f"{label}: the control is disabled (joint sliders are while simulating)"
        problem = check_value(
            handle.value, value, getattr(handle, "min", None), getattr(handle, "max", None)
        )
        options = getattr(handle, "options", None)
        if problem is None and options is not None and value not in options:
            problem = f"{value!r} is not one of the menu's entries"
        return f"{label}: {problem}" if problem else None

    def _refuse_message(self, connection: Any, reason: str) -> None:
        """Record a refused page message and tell that page why."""
        self._note_refusal(f"message from the page: {reason}")
        ws = self.server._websock_server
        ids = [c for c, conn in list(ws._live_connections.items()) if conn is connection]
        client = self.server.get_clients().get(ids[0]) if ids else None
        if client is not None:
            client.add_notification("Refused", reason, color="red", auto_close_seconds=10.0)

    def _note_refusal(self, reason: str) -> None:
        with self._refusals:
            self.refused.append(reason)
            self.refused_count += 1
            self._refusals.notify_all()

    def wait_for_refusals(self, count: int, timeout: float) -> bool:
        """Wait until ``refused_count`` reaches ``count`` (at most ``timeout`` s); True
        when it did. The page's messages are checked on the server's own thread."""
        with self._refusals:
            return self._refusals.wait_for(lambda: self.refused_count >= count, timeout)
