"""Safe XML reading for untrusted robot files (entity declarations and external
references refused, so no entity expansion)."""

from __future__ import annotations

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
        return DET.fromstring(read_bytes(path, MAX_XML_BYTES))
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


def describe(elem: ET.Element) -> str:
    """``<tag name="...">`` for messages."""
    name = elem.get("name")
    return f'<{elem.tag} name="{name}">' if name is not None else f"<{elem.tag}>"
