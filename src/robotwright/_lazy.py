"""Lazy package exports: ``from robotwright.sensors import LidarSensor`` imports the
submodule (and MuJoCo, numpy) only when the name is first used.

The command line imports every subsystem's ``cli`` module to build its parser, which
imports each package's ``__init__``; with eager re-exports that alone imported MuJoCo
and numpy and made ``robotwright --help`` take about a second. A package declares its
exports once, under ``if TYPE_CHECKING:`` (so type checkers and readers see ordinary
imports), and calls :func:`attach` with its ``__name__`` and ``__file__``::

    from typing import TYPE_CHECKING

    from robotwright._lazy import attach

    if TYPE_CHECKING:
        from robotwright.sensors.lidar import LidarSensor

    attach(__name__, __file__)
"""

from __future__ import annotations

import ast
import importlib
import sys
import types
from typing import Any

__all__ = ["attach"]


class _LazyPackage(types.ModuleType):
    """A package module that imports an exported name's submodule on first access."""

    _lazy_exports: dict[str, str]

    def __getattr__(self, name: str) -> Any:
        source = self.__dict__.get("_lazy_exports", {}).get(name)
        if source is None:
            raise AttributeError(f"module {self.__name__!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(source), name)
        types.ModuleType.__setattr__(self, name, value)
        return value

    def __setattr__(self, name: str, value: Any) -> None:
        # The import system binds every imported submodule as an attribute of its
        # package. A submodule named like one of the package's exports (grammar.build
        # holds the function build) must not hide that export, as with eager imports.
        exports = self.__dict__.get("_lazy_exports", {})
        if (
            isinstance(value, types.ModuleType)
            and name in exports
            and value.__name__ == f"{self.__name__}.{name}"
            and exports[name] == value.__name__
        ):
            return
        types.ModuleType.__setattr__(self, name, value)

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self.__dict__.get("_lazy_exports", {})))


def _type_checking_imports(file: str, package: str) -> dict[str, str]:
    """Name -> absolute module of each ``from X import name`` under ``if TYPE_CHECKING:``."""
    with open(file, encoding="utf-8") as fh:
        tree = ast.parse(fh.read(), filename=file)
    exports: dict[str, str] = {}
    for node in tree.body:
        if not (isinstance(node, ast.If) and ast.unparse(node.test).endswith("TYPE_CHECKING")):
            continue
        for stmt in node.body:
            if isinstance(stmt, ast.ImportFrom) and stmt.module is not None:
                module = stmt.module
                if stmt.level:  # relative import: resolve against the package
                    base = package.rsplit(".", stmt.level - 1)[0]
                    module = f"{base}.{module}"
                for alias in stmt.names:
                    if alias.asname not in (None, alias.name):
                        raise ImportError(f"{file}: lazy exports cannot be renamed ({alias.name})")
                    exports[alias.name] = module
    return exports


def attach(package: str, file: str) -> None:
    """Make the names imported under ``if TYPE_CHECKING:`` in ``file`` lazy attributes of
    the package module ``package`` (its ``__name__``; ``file`` is its ``__file__``)."""
    module = sys.modules[package]
    exports = _type_checking_imports(file, package)
    module.__class__ = _LazyPackage
    types.ModuleType.__setattr__(module, "_lazy_exports", exports)
