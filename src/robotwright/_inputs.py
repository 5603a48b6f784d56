"""Reading untrusted input files: regular files only, a size cap, UTF-8, bounded nesting.

A robot folder or grammar file may come from anyone. Whatever it holds, reading it must
end quickly with the data or with one clear error (:class:`InputFileError` naming the
file), never hang, exhaust memory or crash the interpreter:

- only regular files are read: a FIFO, a device (``/dev/urandom``, ``/dev/zero``) or a
  folder in place of a file is refused without opening it for reading (the file is
  opened non-blocking and checked with ``fstat`` before any byte is read);
- each kind of file has a size cap (below); larger files are refused before reading;
- text must be UTF-8;
- YAML and JSON may nest at most :data:`MAX_NESTING` levels (deeper nesting crashes
  libyaml's composer, and exhausts Python's stack in ``json``).

The caps are documented in ``docs/hrdf.md`` ("Untrusted input").
"""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
from typing import Any

import yaml

from robotwright.errors import InputFileError

__all__ = [
    "MAX_NESTING",
    "MJCF_MAX_BODY_DEPTH",
    "MAX_TABLE_BYTES",
    "MAX_XML_BYTES",
    "MAX_YAML_BYTES",
    "copy_regular_file",
    "decode",
    "load_json",
    "load_yaml",
    "read_bytes",
    "read_text",
]

#: meta.yaml, joint_mapping.yaml, grammar and library YAML files, grammar design files.
MAX_YAML_BYTES = 1 << 20
#: Each CSV table of an HRDF folder (a 10,000-body ``body.csv`` is about 2 MB).
MAX_TABLE_BYTES = 64 << 20
#: ``extra.xml``, MJCF and URDF files.
MAX_XML_BYTES = 64 << 20
#: Deepest nesting of YAML/JSON collections (real files nest fewer than 10 levels).
MAX_NESTING = 100
#: Deepest chain of nested bodies an MJCF may hold: MuJoCo's XML reader (tinyxml2)
#: refuses deeper element nesting (measured with MuJoCo 4.0: 496 nested bodies load,
#: 497 do not). MJCF writers refuse deeper trees instead of writing a file MuJoCo cannot
#: read (URDF and HRDF files are flat: any depth).
MJCF_MAX_BODY_DEPTH = 496

# libyaml's C loader is ~20x faster than the pure-Python one; both are "safe" loaders.
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _Yaml12NumbersLoader(_YAML_LOADER):  # type: ignore[misc, valid-type]
    """The safe loader, reading ``1e9`` and ``2E-3`` as numbers as YAML 1.2 does (YAML
    1.1, PyYAML's, wants a dot: ``1.0e9``), so that a configuration's number is never
    refused as text for its spelling."""


_Yaml12NumbersLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _mib(n: int) -> str:
    return f"{n / (1 << 20):.3g} MiB"


def read_bytes(path: str | os.PathLike[str], limit: int) -> bytes:
    """The content of the regular file ``path``, at most ``limit`` bytes.

    Raises:
        InputFileError: not a regular file, or larger than ``limit``.
        OSError: the file cannot be opened (missing, no permission).
    """
    fd, st = _open_regular(path)
    try:
        if st.st_size > limit:
            raise InputFileError(
                path, f"is {_mib(st.st_size)}: larger than the {_mib(limit)} limit for this file"
            )
        chunks: list[bytes] = []
        total = 0
        while True:  # normally one read of the whole file, then one that finds its end
            chunk = os.read(fd, max(st.st_size + 1 - total, 1 << 16))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > limit:  # it grew while being read
                raise InputFileError(path, f"is larger than the {_mib(limit)} limit for this file")
    finally:
        os.close(fd)
    return b"".join(chunks)


def _open_regular(path: str | os.PathLike[str]) -> tuple[int, os.stat_result]:
    """A read descriptor of ``path`` and its status, once it is known to be a regular file
    (opened non-blocking: opening a FIFO does not wait for a writer)."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(path, flags)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise InputFileError(path, f"is {_kind(st.st_mode)}; expected a regular file")
    except BaseException:
        os.close(fd)
        raise
    return fd, st


def copy_regular_file(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
    """Copy the regular file ``src`` to ``dst`` (a FIFO or device is refused unread).

    Raises:
        InputFileError: ``src`` is not a regular file.
        OSError: reading or writing failed.
    """
    fd, _ = _open_regular(src)
    with os.fdopen(fd, "rb") as fin, open(dst, "wb") as fout:
        shutil.copyfileobj(fin, fout, 1 << 20)


def decode(data: bytes, path: str | os.PathLike[str]) -> str:
    """``data`` decoded as UTF-8 (:class:`InputFileError` naming ``path`` if it is not)."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputFileError(
            path,
            f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "expected a UTF-8 file",
        ) from None


def read_text(path: str | os.PathLike[str], limit: int) -> str:
    """The UTF-8 text of the regular file ``path`` (see :func:`read_bytes`), line endings
    made ``\n`` as ``Path.read_text`` does (universal newlines)."""
    text = decode(read_bytes(path, limit), path)
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    return text


_DEEP_INDENT = re.compile(rf"^[ \t?:-]{{{MAX_NESTING // 4},}}", re.MULTILINE)


def _yaml_depth_ok(text: str) -> bool:
    """Whether ``text`` nests at most :data:`MAX_NESTING` collections.

    Few flow brackets and shallow indentation bound the depth well below the limit, so
    the exact count (walking libyaml's events, no recursion) only runs for texts that
    could be deep.
    """
    if text.count("[") + text.count("{") < MAX_NESTING // 4 and not _DEEP_INDENT.search(text):
        return True
    depth = 0
    starts = (yaml.MappingStartEvent, yaml.SequenceStartEvent)
    ends = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
    for event in yaml.parse(text, Loader=_YAML_LOADER):
        if isinstance(event, starts):
            depth += 1
            if depth > MAX_NESTING:
                return False
        elif isinstance(event, ends):
            depth -= 1
    return True


def load_yaml(
    path: str | os.PathLike[str], limit: int = MAX_YAML_BYTES, *, exponent_floats: bool = False
) -> Any:
    """The YAML document in file ``path`` (safe loader; regular file, size cap, UTF-8,
    nesting checked); with ``exponent_floats``, ``1e9`` is read as a number (YAML 1.2)
    rather than as text (YAML 1.1).

    Raises:
        InputFileError: see :func:`read_bytes`, not UTF-8, or nested too deep.
        yaml.YAMLError: not valid YAML.
        OSError: the file cannot be opened.
    """
    text = read_text(path, limit)
    if not _yaml_depth_ok(text):
        raise InputFileError(
            path, f"nests more than {MAX_NESTING} levels of lists/mappings; refused"
        )
    return yaml.load(text, Loader=_Yaml12NumbersLoader if exponent_floats else _YAML_LOADER)


def load_json(text: str, source: str | os.PathLike[str]) -> Any:
    """The JSON value in ``text`` (``source`` names it in errors).

    Raises:
        InputFileError: nested too deep for Python's stack.
        json.JSONDecodeError: not valid JSON.
    """
    try:
        return json.loads(text)
    except RecursionError:
        raise InputFileError(
            source, "nests lists/objects too deeply (Python's recursion limit); refused"
        ) from None
