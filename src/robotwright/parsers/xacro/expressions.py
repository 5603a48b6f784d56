"""The ``${...}`` and ``$(eval ...)`` expressions of xacro files, evaluated without Python.

xacro evaluates expressions with Python's ``eval`` and only refuses names that start
with ``__``; strings, the ``python`` namespace (``type``, ``vars``) and format strings
reach the interpreter's internals and from there any code. A downloaded robot is
untrusted input, so its expressions are evaluated here instead, by walking the syntax
tree that :func:`ast.parse` gives (``mode="eval"``) over an allow-list; every other node,
name, attribute or call is refused with :class:`ExpressionError`, which names the
expression and the construct. Nothing is compiled and nothing is looked up on Python
objects by a name the file chooses, except the allow-listed attributes below.

What is evaluated (the same values Python's ``eval`` gives for them):

- literals: numbers (``int``, ``float``), strings, ``True``/``False``/``None``; lists,
  tuples, dicts and sets of expressions (with ``*``/``**`` unpacking);
- operators: ``+ - * / // % **``, ``<< >> & | ^ ~``, unary ``- + not``, comparisons
  (``< <= == != > >= in not in is is not``, chained), ``and``/``or``, ``a if c else b``;
- subscripts and slices of strings, lists, tuples, dicts and the YAML values of
  ``xacro.load_yaml``;
- list, set and dict comprehensions and generator expressions (evaluated at once, as a
  list); their loop names are local to the comprehension;
- names: the loop names above, the file's properties (and macro parameters), then the
  functions and constants xacro documents (:data:`TOP_LEVEL`): the ``math`` module's
  public functions and constants (also as ``math.NAME``), ``min``, ``max``,
  ``round``, ``len``, ``int``, ``float``, ``str``, ``bool``, ``list``, ``dict``, ``map``,
  ``sorted``, ``range`` and the safe part of the ``python.`` namespace
  (:data:`PYTHON_NAMESPACE`);
- attributes only on: the ``math``, ``python`` and ``xacro`` namespaces and a file's
  include namespaces (``<xacro:include ns=...>``); YAML dicts (a key, as xacro's
  ``YamlDictWrapper`` gives it); and the side-effect-free methods of strings, lists,
  tuples and dicts in :data:`METHODS` (no ``format``/``format_map``: format strings
  look up attributes by name). No attribute starting with ``_`` anywhere;
- calls only of the functions and methods above.

Refused: lambdas, f-strings, the walrus operator, ``await``/``yield``, attribute access
on anything else (numbers, functions, the values of other types), ``type``, ``vars``,
``getattr``, ``eval``, ``exec``, ``compile``, ``open``, ``__import__``, ``globals``,
``locals`` and every other builtin not listed. Results are capped so one expression
cannot exhaust memory (``9**9**9``, ``'a' * 10**10``): integers of at most
:data:`MAX_INT_BITS` bits, strings of at most :data:`MAX_STR` characters, containers
of at most :data:`MAX_ITEMS` items (counted through nesting), ``%`` format widths of at
most :data:`MAX_WIDTH`, and :data:`MAX_STEPS` evaluation steps per expression.

Why not a library: ``simpleeval`` and ``asteval`` evaluate over live Python objects with
a deny-list of attribute names, and have been escaped through what the deny-list
missed (generator ``gi_frame.f_globals``, ``__reduce__``, function globals, the
``operator`` module, format strings); an allow-list of node types, names, attributes
and value types is small enough to review whole, so the evaluator is written here.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from robotwright.parsers.xacro.evaluator import Evaluator
from robotwright.parsers.xacro.names import (
    _UNSET,
    MAX_STEPS,  # noqa: F401
    ExpressionError,
    Namespace,
    SafeFunction,
    _checked,
    _str,
    default_names,
)

#: The ``xacro.`` functions expressions may call (xacro's own: ``load_yaml`` opens files
#: through the ``open`` the caller installs, which applies the containment rules).
XACRO_NAMESPACE: frozenset[str] = frozenset(
    [
        "load_yaml",
        "abs_filename",
        "dotify",
        "arg",
        "message",
        "warning",
        "error",
        "print_location",
        "fatal",
        "tokenize",
    ]
)

#: xacro's deprecated direct names for three of them (xacro warns when they are used).
XACRO_DIRECT: frozenset[str] = frozenset({"load_yaml", "abs_filename", "dotify"})


def _dotify_guard(value: Any = None, *_: Any, **__: Any) -> None:
    if type(value) is not dict:
        raise ExpressionError("xacro.dotify() takes a dict")


def _relative_filename(xacro: Any) -> Callable[[str], str]:
    """xacro's ``abs_filename``, made to answer relative to the top-level file's folder
    (``/``-separated) instead of with the absolute path: the same file for the mesh
    resolver (which resolves from that folder), and the user's folder layout never
    reaches the output (a link named after it, say)."""

    def abs_filename(spec: Any) -> str:
        if not isinstance(spec, str):
            raise ExpressionError("xacro.abs_filename() takes a file name")
        stack = xacro.filestack or [None]
        here = os.path.dirname(os.path.abspath(stack[-1])) if stack[-1] else os.getcwd()
        top = os.path.dirname(os.path.abspath(stack[0])) if stack[0] else os.getcwd()
        full = os.path.normpath(os.path.join(here, spec))
        return Path(os.path.relpath(full, top)).as_posix()

    return abs_filename


def _no_eval(*_: Any, **__: Any) -> Any:
    raise ExpressionError("Python evaluation is disabled for xacro files")


def xacro_evaluators(xacro: Any, substitution_args: Any) -> tuple[Callable, Callable]:
    """Replacements for ``xacro.safe_eval(expr, symbols)`` and
    ``substitution_args._eval(expr, context)`` (``$(eval ...)``) built from the
    installed xacro module's own tables and functions."""
    table = xacro.Table
    root = xacro._global_symbols
    ns = dict.__getitem__(root, "xacro")
    own = {"abs_filename": _relative_filename(xacro)}

    def function(table_: dict, name: str, shown_as: str) -> SafeFunction:
        return SafeFunction(
            shown_as,
            own.get(name) or dict.__getitem__(table_, name),
            _dotify_guard if name == "dotify" else None,
        )

    xacro_ns = Namespace(
        "xacro",
        {
            name: function(ns, name, f"xacro.{name}")
            for name in XACRO_NAMESPACE
            if dict.__contains__(ns, name)
        },
    )
    names = default_names()
    names["xacro"] = xacro_ns
    for name in XACRO_DIRECT:
        if dict.__contains__(root, name):
            names[name] = function(root, name, name)
    dotted = (xacro.YamlDictWrapper, xacro.YamlListWrapper)

    def walk(symbols: Any, name: str) -> Any:
        # Only the file's own tables: the walk stops at xacro's global symbols (a plain
        # dict), whose functions are replaced by ``names``.
        current = symbols
        while isinstance(current, table):
            if dict.__contains__(current, name):
                return current[name]
            current = current.parent
        raise KeyError(name)

    def safe_eval(expr: str, symbols: Any, _locals: Any = None) -> Any:
        evaluator = Evaluator(
            lambda name: walk(symbols, name),
            names,
            dotted=dotted,
            scopes=(xacro.NameSpace,),
            scope_lookup=walk,
        )
        return evaluator.evaluate(expr)

    def eval_substitution(expr: str, context: dict) -> str:
        context.setdefault("arg", {})
        args = context["arg"]
        functions: dict[str, Any] = {
            "arg": SafeFunction(
                "arg",
                lambda name: substitution_args.convert_value(
                    substitution_args._eval_arg(name, args=args), "auto"
                ),
            ),
            "dirname": SafeFunction(
                "dirname", lambda: substitution_args._eval_dirname(context["filename"])
            ),
        }
        for name in ("find", "env", "optenv"):
            functions[name] = SafeFunction(name, substitution_args._eval_dict[name])

        def lookup(name: str) -> Any:
            if name in functions:
                return functions[name]
            return substitution_args.convert_value(args[name], "auto")

        value = Evaluator(lookup, default_names()).evaluate(expr)
        return _checked(_str(value), "$(eval)")

    return safe_eval, eval_substitution


class installed:  # noqa: N801 - used as a context manager, like contextlib's
    """Within ``with installed(xacro, substitution_args):`` xacro evaluates every
    ``${...}`` (attributes, text, ``<xacro:if>``, properties, macro arguments, YAML unit
    tags) and every ``$(eval ...)`` with :class:`Evaluator`; its module-level name
    ``eval`` is shadowed by a function that refuses, so no path left in xacro reaches
    Python's ``eval``."""

    def __init__(self, xacro: Any, substitution_args: Any) -> None:
        self.modules = (xacro, substitution_args)
        self.safe_eval, self.eval_substitution = xacro_evaluators(xacro, substitution_args)
        self.saved: list[tuple[Any, str, Any]] = []

    def _set(self, module: Any, name: str, value: Any) -> None:
        self.saved.append((module, name, vars(module).get(name, _UNSET)))
        setattr(module, name, value)

    def __enter__(self) -> installed:
        xacro, substitution_args = self.modules
        self._set(xacro, "safe_eval", self.safe_eval)
        self._set(substitution_args, "_eval", self.eval_substitution)
        self._set(xacro, "eval", _no_eval)
        self._set(substitution_args, "eval", _no_eval)
        return self

    def __exit__(self, *_: Any) -> None:
        for module, name, value in reversed(self.saved):
            if value is _UNSET:
                delattr(module, name)
            else:
                setattr(module, name, value)
        self.saved.clear()
