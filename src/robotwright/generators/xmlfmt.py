"""Deterministic XML writing: float formatting, attribute helpers, atomic file output.

Floats are written with Python's shortest round-trip representation (``repr``), so a
value read back is bit-identical to the one written; integral values drop their ``.0``
and ``-0.0`` is written as ``0``. Attribute order is insertion order, so the same input
always gives the same bytes.
"""

from __future__ import annotations

import os
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

XML_HEADER = '<?xml version="1.0" encoding="utf-8"?>\n'


def fmt_float(value: float) -> str:
    """Shortest exact text for ``value`` (``1.0`` -> ``"1"``, ``-0.0`` -> ``"0"``)."""
    v = float(value)
    if v == 0.0:
        return "0"
    text = repr(v)
    if text.endswith(".0"):
        return text[:-2]
    return text


def fmt_vec(values: Iterable[float]) -> str:
    """Space-separated :func:`fmt_float` values."""
    return " ".join(fmt_float(v) for v in values)


def prefixed(prefix: str | None, name: str) -> str:
    """``<prefix>_<name>`` (hurodes' convention), or ``name`` when there is no prefix."""
    return f"{prefix}_{name}" if prefix else name


def to_xml_string(root: ET.Element) -> str:
    """The element as an indented document with an XML header (2-space indent)."""
    ET.indent(root, space="  ", level=0)
    return XML_HEADER + ET.tostring(root, encoding="unicode") + "\n"


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder and a rename,
    so readers never see a partial file and a failed write leaves no file behind."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def copy_file_atomic(src: Path, dst: Path) -> None:
    """Copy ``src`` to ``dst`` through a temporary file and a rename."""
    import shutil

    dst.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{dst.name}.", suffix=".tmp", dir=dst.parent)
    os.close(fd)
    try:
        shutil.copyfile(src, tmp)
        os.replace(tmp, dst)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
