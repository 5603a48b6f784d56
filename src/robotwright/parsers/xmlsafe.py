"""Safe XML reading for untrusted robot files (entity declarations and external
references refused, so no entity expansion)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml
import defusedxml.ElementTree as DET

from robotwright.errors import ConversionError, Problem


def parse_xml(path: Path) -> ET.Element:
    """Root element of the XML file at ``path``.

    Raises:
        ConversionError: the file is missing, not well-formed, or declares XML entities
            features (refused: they allow entity-expansion and external-entity attacks).
    """
    try:
        return DET.parse(str(path)).getroot()
    except FileNotFoundError as exc:
        raise ConversionError([Problem(str(path), "file not found")]) from exc
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
