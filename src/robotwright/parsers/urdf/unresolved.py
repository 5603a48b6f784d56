"""Unresolved ``package://`` meshes told once per package, not once per mesh.

A URDF whose package is not found names it in every mesh (20 to 79 in a typical
robot); the reader's refusal lists one line per missing package instead: the package,
how many meshes name it and the first element, and the two ways to name its folder
(``--package NAME=DIR``, ``ROS_PACKAGE_PATH``). Other unresolved meshes (a missing
file, a path leaving its folder) keep one line each: each is a different file.
"""

from __future__ import annotations

import re

from robotwright.errors import Problem

__all__ = ["group_unresolved"]

#: The start of :func:`robotwright.parsers.packages.package_not_found`'s message.
_NOT_FOUND = re.compile(r"^package '([^']*)' not found inside (.*?) \(the folder of")


def group_unresolved(problems: list[Problem]) -> list[Problem]:
    """``problems`` with every "package not found" of one package made one problem."""
    by_package: dict[str, list[Problem]] = {}
    out: list[Problem | str] = []
    for p in problems:
        m = _NOT_FOUND.match(p.message)
        if m is None:
            out.append(p)
            continue
        if m.group(1) not in by_package:
            out.append(m.group(1))  # where the package's line goes
        by_package.setdefault(m.group(1), []).append(p)
    return [item if isinstance(item, Problem) else _one(item, by_package[item]) for item in out]


def _one(name: str, found: list[Problem]) -> Problem:
    first = found[0]
    root = _NOT_FOUND.match(first.message).group(2)  # type: ignore[union-attr]
    shown = name if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.+-]*", name) else "NAME"
    return Problem(
        first.file,
        f"package '{name}' not found inside {root} nor in ROS_PACKAGE_PATH or "
        f"AMENT_PREFIX_PATH ({len(found)} mesh(es) name it); name its folder with "
        f"--package {shown}=DIR (package_map in Python), or add the folder holding it to "
        "ROS_PACKAGE_PATH",
        element=first.element,
    )
