"""Safe XML reading for untrusted robot files (entity declarations and external
references refused, so no entity expansion)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml
import defusedxml.ElementTree as DET

from robotwright._inputs import MAX_XML_BYTES, read_bytes
from robotwright.errors import ConversionError, InputFileError, Problem


def parse_xml(path: Path) -> ET.Element:
    """Root element of the XML file at ``path``.

    Raises:
        ConversionError: the file is missing, not a regular file (a FIFO, a device),
            larger than :data:`~robotwright._inputs.MAX_XML_BYTES`, not well-formed, or
            declares XML entities features (refused: they allow entity-expansion and
            external-entity attacks).
    """
    try:
        data = read_bytes(path, MAX_XML_BYTES)
        try:
            return DET.fromstring(data)
        except ET.ParseError:
            lenient = _as_mujoco_reads(data)
            if lenient == data:
                raise
            try:
                return DET.fromstring(lenient)
            except ET.ParseError:
                pass
            raise
    except FileNotFoundError as exc:
        raise ConversionError([Problem(str(path), "file not found")]) from exc
    except InputFileError as exc:
        raise ConversionError([Problem(str(path), exc.reason)]) from exc
    except defusedxml.DefusedXmlException as exc:
        raise ConversionError(
            [Problem(str(path), f"unsafe XML refused ({type(exc).__name__}): {exc}")]
        ) from exc
    except ET.ParseError as exc:
        raise ConversionError([Problem(str(path), f"not well-formed XML: {exc}")]) from exc


# Two attributes with no space between them (`a="1"b="2"`), which MuJoCo's reader
# (tinyxml2) accepts: a closing quote directly followed by the next attribute's name.
_GLUED_ATTRS = re.compile(
    rb"""(\s[\w:.-]+\s*=\s*(?:"[^"<]*"|'[^'<]*'))(?=[A-Za-z_:][\w:.-]*\s*=)"""
)


def _as_mujoco_reads(data: bytes) -> bytes:
    """What MuJoCo's XML reader reads of a file our strict parser refuses: the text up
    to the first NUL byte (it reads C strings), without the blank lines before the XML
    declaration, with a space between attributes written without one. Entities and
    external references are still refused by the parse that follows."""
    data = data.split(b"\0", 1)[0].lstrip()
    return _GLUED_ATTRS.sub(rb"\1 ", data)


def describe(elem: ET.Element) -> str:
    """``<tag name="...">`` for messages."""
    name = elem.get("name")
    return f'<{elem.tag} name="{name}">' if name is not None else f"<{elem.tag}>"
