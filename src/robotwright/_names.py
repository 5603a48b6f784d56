"""What a name read from an input (a body, joint, site, rule...) may hold, and how text
from inputs is shown on a terminal.

Names are written into XML attributes, CSV cells and design files, and printed in
messages. A name holding a control character cannot be written to XML at all (XML 1.0
has no way to hold most of them), a newline breaks line-based files such as
``design.txt``, and escape sequences or bidirectional overrides printed raw change what
the user's terminal shows. So names are refused when they hold:

- a C0 control character (``U+0000``-``U+001F``, tab and newline included), ``DEL``
  (``U+007F``) or a C1 control character (``U+0080``-``U+009F``);
- a Unicode bidirectional formatting character (``U+061C``, ``U+200E``, ``U+200F``,
  ``U+202A``-``U+202E``, ``U+2066``-``U+2069``) or a line/paragraph separator
  (``U+2028``, ``U+2029``);
- more than :data:`MAX_NAME_LENGTH` characters.

Caps are documented in ``docs/hrdf.md`` ("Untrusted input").
"""

from __future__ import annotations

import re
from typing import Any, TextIO

__all__ = [
    "MAX_NAME_LENGTH",
    "MAX_SHOWN_CHARS",
    "MAX_STEM_CHARS",
    "UNSAFE_CHARS",
    "PrintableStream",
    "file_stem",
    "name_problem",
    "printable",
    "shown",
    "shown_key",
]

#: Longest name accepted [characters]. Real robots' names are under 100 characters;
#: generated ones (enumerated copies, prefixed scene parts) stay far below this.
MAX_NAME_LENGTH = 1024

_BIDI = "\u061c\u200e\u200f\u2028\u2029\u202a-\u202e\u2066-\u2069"
#: Characters a name may not hold (see the module doc).
UNSAFE_CHARS = re.compile(f"[\x00-\x1f\x7f-\x9f{_BIDI}]")
# The same, except the newline and tab that messages are made of.
_UNSAFE_IN_TEXT = re.compile(f"[\x00-\x08\x0b-\x1f\x7f-\x9f{_BIDI}]")


def name_problem(name: str) -> str | None:
    """Why ``name`` is refused (to follow "name '...'"), or None when it is fine."""
    if len(name) > MAX_NAME_LENGTH:
        return f"is {len(name)} characters long: expected at most {MAX_NAME_LENGTH}"
    bad = UNSAFE_CHARS.search(name)
    if bad is not None:
        return (
            f"holds the character {_escape(bad.group())} at index {bad.start()}: names may "
            "not hold control or bidirectional formatting characters"
        )
    return None


#: Longest file or folder name made from a name read from an input [characters]; file
#: systems allow 255 bytes, and a suffix or a counter is often added.
MAX_STEM_CHARS = 64
_NOT_IN_STEM = re.compile(r"[^A-Za-z0-9_.-]")


def file_stem(name: object, fallback: str) -> str:
    """A single, harmless file or folder name made from ``name``, a name read from an
    input file (a URDF ``<robot name="../../x">``, a model's name): the one rule by which
    a name becomes part of a path. Every character but ASCII letters, digits, ``_``,
    ``-`` and ``.`` becomes ``_`` (so no separator, ``\\``, NUL or control character
    survives), runs of dots become ``_`` (no ``..``), leading and trailing dots go (no
    hidden file, never ``.``), and the result is cut to :data:`MAX_STEM_CHARS`.
    ``fallback`` (itself a safe stem) is used where nothing is left."""
    text = name if isinstance(name, str) else ""
    safe = _NOT_IN_STEM.sub("_", text[: 4 * MAX_STEM_CHARS])
    safe = re.sub(r"\.{2,}", "_", safe).strip(".")[:MAX_STEM_CHARS].rstrip(".")
    return safe or fallback


#: Longest piece of an input's value shown in a message [characters].
MAX_SHOWN_CHARS = 200


def shown(value: object, limit: int = MAX_SHOWN_CHARS, _depth: int = 0) -> str:
    """``value`` as a message shows a value read from an input: its ``repr``, cut to
    about ``limit`` characters. Mappings and lists show their first items, two levels
    deep, and their size, so that a huge or deeply aliased value (a YAML alias bomb)
    costs no more to show than a few items."""
    if isinstance(value, (dict, list, tuple)):
        kind = {dict: "mapping", list: "list"}.get(type(value), "tuple")
        if _depth >= 2:
            text = f"(a {kind} of {len(value)})"
        else:
            items = list(value.items())[:4] if isinstance(value, dict) else list(value[:4])
            parts = [
                f"{shown(i[0], 40, _depth + 1)}: {shown(i[1], 40, _depth + 1)}"
                if isinstance(value, dict)
                else shown(i, 40, _depth + 1)
                for i in items
            ]
            more = ", ..." if len(value) > 4 else ""
            opening, closing = ("{", "}") if isinstance(value, dict) else ("[", "]")
            text = f"{opening}{', '.join(parts)}{more}{closing} (a {kind} of {len(value)})"
    elif isinstance(value, str):
        text = repr(value[: limit + 1])
    elif isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 600:
        text = f"an integer of {value.bit_length()} bits"
    else:
        text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def shown_key(key: object, limit: int = 80) -> str:
    """A mapping key read from an input, as a message names a field: a text as it is,
    anything else as :func:`shown` gives it; cut to ``limit`` characters."""
    if isinstance(key, str):
        return key if len(key) <= limit else key[: limit - 3] + "..."
    return shown(key, limit)


def _escape(char: str) -> str:
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def printable(text: str) -> str:
    """``text`` with every control and bidirectional formatting character shown as an
    escape (``\\x1b``, ``\\u202e``), newlines and tabs kept: what a terminal may be
    given of text that came from an input file."""
    if _UNSAFE_IN_TEXT.search(text) is None:
        return text
    return _UNSAFE_IN_TEXT.sub(lambda m: _escape(m.group()), text)


class PrintableStream:
    """A text stream that writes :func:`printable` text to ``stream``: the command line
    wraps ``sys.stdout`` and ``sys.stderr`` in it while a command runs, so that no
    message or listing (a name, a CSV cell, a path quoted in an error) can send escape
    sequences to the user's terminal. Everything else is the wrapped stream's."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        self._stream.write(printable(text))
        return len(text)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)
