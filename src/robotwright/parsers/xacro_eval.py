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

import ast
import math
import operator
import re
from collections.abc import Callable, Iterable, Mapping
from typing import Any

#: Caps of one expression (see the module docstring).
MAX_INT_BITS = 4096
MAX_STR = 1_000_000
MAX_ITEMS = 1_000_000
MAX_WIDTH = 10_000
MAX_STEPS = 5_000_000


class ExpressionError(Exception):
    """An expression is refused or fails; the message names the expression and why."""


class _Unset:
    pass


_UNSET = _Unset()

# ---------------------------------------------------------------- value checks

_SCALARS = (int, float, bool, type(None), str)
_CONTAINERS = (list, tuple, dict, set, frozenset)


def _size(value: Any, budget: int) -> int:
    """Items in ``value`` counted through nesting (shared parts counted each time they
    appear, as ``str()`` would write them), stopping once over ``budget``."""
    total = 0
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            total += len(item) // 16  # strings count by their own cap; a little here
        elif isinstance(item, (list, tuple, set, frozenset)):
            total += len(item)
            stack.extend(x for x in item if isinstance(x, (*_CONTAINERS, str)))
        elif isinstance(item, dict):
            total += len(item)
            stack.extend(x for x in item.values() if isinstance(x, (*_CONTAINERS, str)))
        if total > budget:
            break
    return total


def _checked(value: Any, what: str) -> Any:
    """``value`` when it is within the caps, else :class:`ExpressionError`."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        if value.bit_length() > MAX_INT_BITS:
            raise ExpressionError(f"{what}: an integer over {MAX_INT_BITS} bits is refused")
    elif isinstance(value, str):
        if len(value) > MAX_STR:
            raise ExpressionError(f"{what}: a string over {MAX_STR} characters is refused")
    elif isinstance(value, _CONTAINERS) and _size(value, MAX_ITEMS) > MAX_ITEMS:
        raise ExpressionError(f"{what}: a value over {MAX_ITEMS} items is refused")
    return value


def _length(value: Any) -> int | None:
    """Length of a sequence operand (for cap checks before the operation)."""
    if isinstance(value, (str, list, tuple)):
        return len(value)
    return None


def _is_int(value: Any) -> bool:
    return isinstance(value, int)


# ---------------------------------------------------------------- callables


class SafeFunction:
    """A function the evaluator may call: ``fn`` under ``name``, its result checked.

    A plain class (not a closure) so that nothing of the wrapped function's globals is
    reachable from it; the evaluator never reads attributes of it anyway.
    """

    __slots__ = ("name", "_fn", "_guard")

    def __init__(
        self, name: str, fn: Callable[..., Any], guard: Callable[..., None] | None = None
    ) -> None:
        self.name = name
        self._fn = fn
        self._guard = guard

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        for value in (*args, *kwargs.values()):
            if callable(value) and not isinstance(value, (SafeFunction, _Method)):
                raise ExpressionError(f"{self.name}(): a {type(value).__name__} is refused")
        if self._guard is not None:
            self._guard(*args, **kwargs)
        return _checked(self._fn(*args, **kwargs), f"{self.name}()")

    def __repr__(self) -> str:
        return f"<function {self.name}>"


class _Method:
    """A bound, allow-listed method of a string, list, tuple or dict value."""

    __slots__ = ("_obj", "_name")

    def __init__(self, obj: Any, name: str) -> None:
        self._obj = obj
        self._name = name

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        guard = _METHOD_GUARDS.get(self._name)
        if guard is not None:
            guard(self._obj, *args, **kwargs)
        for value in (*args, *kwargs.values()):
            if callable(value) and not isinstance(value, (SafeFunction, _Method)):
                raise ExpressionError(f".{self._name}(): a {type(value).__name__} is refused")
        result = getattr(self._obj, self._name)(*args, **kwargs)
        return _checked(result, f".{self._name}()")

    def __repr__(self) -> str:
        return f"<method {self._name} of {type(self._obj).__name__}>"


class Namespace:
    """A fixed set of names reached with ``ns.NAME`` (``math``, ``python``, ``xacro``)."""

    __slots__ = ("name", "members")

    def __init__(self, name: str, members: Mapping[str, Any]) -> None:
        self.name = name
        self.members = dict(members)

    def __repr__(self) -> str:
        return f"<namespace {self.name}>"


def _width_guard(obj: Any, width: Any = 0, *_: Any, **__: Any) -> None:
    if _is_int(width) and width > MAX_WIDTH:
        raise ExpressionError(f"a width over {MAX_WIDTH} is refused")


def _replace_guard(obj: Any, old: Any = "", new: Any = "", count: Any = -1) -> None:
    if isinstance(obj, str) and isinstance(old, str) and isinstance(new, str):
        n = obj.count(old) if old else len(obj) + 1
        if _is_int(count) and count >= 0:
            n = min(n, count)
        if len(obj) + n * max(0, len(new) - len(old)) > MAX_STR:
            raise ExpressionError(f"replace(): a string over {MAX_STR} characters is refused")


def _join_guard(obj: Any, items: Any = (), *_: Any) -> None:
    if isinstance(obj, str) and isinstance(items, (list, tuple)):
        total = len(obj) * max(0, len(items) - 1)
        total += sum(len(x) for x in items if isinstance(x, str))
        if total > MAX_STR:
            raise ExpressionError(f"join(): a string over {MAX_STR} characters is refused")


_METHOD_GUARDS: dict[str, Callable[..., None]] = {
    "center": _width_guard,
    "ljust": _width_guard,
    "rjust": _width_guard,
    "zfill": _width_guard,
    "replace": _replace_guard,
    "join": _join_guard,
}

#: The methods that may be called on values of each type: none changes its value,
#: none formats by field names (``format``), none takes a width without a cap.
METHODS: dict[type, frozenset[str]] = {
    str: frozenset(
        [
            "capitalize",
            "casefold",
            "center",
            "count",
            "endswith",
            "find",
            "index",
            "isalnum",
            "isalpha",
            "isdecimal",
            "isdigit",
            "isidentifier",
            "islower",
            "isnumeric",
            "isspace",
            "istitle",
            "isupper",
            "join",
            "ljust",
            "lower",
            "lstrip",
            "partition",
            "removeprefix",
            "removesuffix",
            "replace",
            "rfind",
            "rindex",
            "rjust",
            "rpartition",
            "rsplit",
            "rstrip",
            "split",
            "splitlines",
            "startswith",
            "strip",
            "swapcase",
            "title",
            "upper",
            "zfill",
        ]
    ),
    list: frozenset({"count", "index", "copy"}),
    tuple: frozenset({"count", "index"}),
    dict: frozenset({"get", "keys", "values", "items", "copy"}),
    float: frozenset({"is_integer"}),
}


# ---------------------------------------------------------------- the functions


def _range_guard(*args: Any) -> None:
    if len(range(*args)) > MAX_ITEMS:
        raise ExpressionError(f"range(): over {MAX_ITEMS} items is refused")


def _range(*args: Any) -> list[int]:
    # A list, not a range object: a range has attributes (start, stop) and a lazy
    # length; xacro files only iterate, index or print it.
    return list(range(*args))


def _map(fn: Any, *iterables: Any) -> list[Any]:
    if not isinstance(fn, (SafeFunction, _Method)):
        raise ExpressionError("map(): only the allowed functions may be mapped")
    return list(map(fn, *iterables))


def _str(value: Any = "") -> str:
    if isinstance(value, _CONTAINERS) and _size(value, MAX_STR // 4) > MAX_STR // 4:
        raise ExpressionError(f"str(): a string over {MAX_STR} characters is refused")
    return str(value)


def _math_guard(name: str) -> Callable[..., None]:
    def guard(*args: Any, **kwargs: Any) -> None:
        for value in (*args, *kwargs.values()):
            if _is_int(value) and value.bit_length() > MAX_INT_BITS:
                raise ExpressionError(f"math.{name}(): an integer over {MAX_INT_BITS} bits")
        if name in ("factorial", "comb", "perm") and any(
            _is_int(v) and abs(v) > 1500 for v in args
        ):
            raise ExpressionError(f"math.{name}(): arguments over 1500 are refused")
        if name == "prod" and args:
            _prod_guard(args[0])

    return guard


def _prod_guard(values: Any) -> None:
    """``math.prod`` of integers whose product would pass :data:`MAX_INT_BITS` bits is
    refused before it is computed (``math.prod(range(1, 999999))`` runs for minutes)."""
    bits = 0
    for value in values if isinstance(values, (list, tuple, range)) else ():
        if _is_int(value) and value:
            bits += abs(value).bit_length()
            if bits > MAX_INT_BITS + 64:
                raise ExpressionError(f"math.prod(): a product over {MAX_INT_BITS} bits")


def _round_guard(number: Any = None, ndigits: Any = None) -> None:
    """``round(x, n)`` with ``|n|`` over :data:`MAX_INT_BITS` computes ``10**|n|``
    (``round(10**1000, -10**9)`` runs for minutes): refused."""
    if _is_int(ndigits) and abs(ndigits) > MAX_INT_BITS:
        raise ExpressionError(f"round(): ndigits over {MAX_INT_BITS} in size is refused")


def _math_members() -> dict[str, Any]:
    members: dict[str, Any] = {}
    for name, value in vars(math).items():
        if name.startswith("_"):
            continue
        if isinstance(value, float):
            members[name] = value
        elif callable(value):
            members[name] = SafeFunction(f"math.{name}", value, _math_guard(name))
    return members


def _plain(name: str, fn: Callable[..., Any], guard: Callable[..., None] | None = None) -> Any:
    return SafeFunction(name, fn, guard)


def _builtins() -> dict[str, Any]:
    """The builtins xacro exposes, less those that reach Python's internals."""
    return {
        "abs": _plain("abs", abs),
        "all": _plain("all", all),
        "any": _plain("any", any),
        "bool": _plain("bool", bool),
        "dict": _plain("dict", dict),
        "divmod": _plain("divmod", divmod),
        "enumerate": _plain("enumerate", lambda *a, **k: list(enumerate(*a, **k))),
        "float": _plain("float", float),
        "int": _plain("int", int),
        "len": _plain("len", len),
        "list": _plain("list", list),
        "map": _plain("map", _map),
        "max": _plain("max", max),
        "min": _plain("min", min),
        "ord": _plain("ord", ord),
        "range": _plain("range", _range, _range_guard),
        "reversed": _plain("reversed", lambda x: list(reversed(x))),
        "round": _plain("round", round, _round_guard),
        "sorted": _plain("sorted", sorted),
        "str": _plain("str", _str),
        "sum": _plain("sum", sum),
        "tuple": _plain("tuple", tuple),
        "zip": _plain("zip", lambda *a: list(zip(*a))),
    }


_BUILTINS = _builtins()

#: Members of the ``python.`` namespace: xacro's, less ``type``, ``vars``,
#: ``isinstance``, ``issubclass``, ``hash``, ``complex``, ``filter``, ``slice``,
#: ``set``, ``frozenset`` and ``repr`` (introspection, or values without a stable text).
PYTHON_NAMESPACE: frozenset[str] = frozenset(_BUILTINS)

#: Names usable directly (xacro's global symbols, less its ``python`` builtins beyond
#: these); ``math``, ``python`` and ``xacro`` are namespaces.
TOP_LEVEL: frozenset[str] = frozenset(
    [
        "list",
        "dict",
        "map",
        "len",
        "str",
        "float",
        "int",
        "bool",
        "min",
        "max",
        "round",
        "sorted",
        "range",
    ]
)

_MATH = _math_members()
MATH_NAMESPACE = Namespace("math", _MATH)
PYTHON = Namespace("python", {k: _BUILTINS[k] for k in PYTHON_NAMESPACE})


def default_names() -> dict[str, Any]:
    """The names every expression sees (before the ``xacro`` namespace is added)."""
    names: dict[str, Any] = dict(_MATH)
    names.update({k: _BUILTINS[k] for k in TOP_LEVEL})
    names["math"] = MATH_NAMESPACE
    names["python"] = PYTHON
    return names


# ---------------------------------------------------------------- the evaluator

_BINOPS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
    ast.LShift: operator.lshift,
    ast.RShift: operator.rshift,
    ast.BitOr: operator.or_,
    ast.BitXor: operator.xor,
    ast.BitAnd: operator.and_,
}
_UNARY: dict[type, Callable[[Any], Any]] = {
    ast.USub: operator.neg,
    ast.UAdd: operator.pos,
    ast.Not: operator.not_,
    ast.Invert: operator.invert,
}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.Is: operator.is_,
    ast.IsNot: operator.is_not,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}

#: ``%`` conversions: an optional key, flags, width and precision (digits; ``*`` is
#: refused as the width would come from the arguments).
_PERCENT = re.compile(r"%(?:\([^)]*\))?[#0\- +]*(\*|\d*)(?:\.(\*|\d*))?[hlL]?(.)", re.S)

#: Errors of a value-level operation (a division by zero, a missing key, a wrong type)
#: that are the file's fault and are reported as such.
_VALUE_ERRORS = (
    ArithmeticError,
    ValueError,
    TypeError,
    KeyError,
    IndexError,
    AttributeError,
    RecursionError,
    MemoryError,
)


_VIEWS = (type({}.keys()), type({}.values()), type({}.items()))
_ITERABLE = (str, list, tuple, dict, set, frozenset, *_VIEWS)


class Evaluator:
    """Evaluates expressions over ``lookup`` (the file's names: raises ``KeyError``
    for a name it does not hold) and ``names`` (the allowed functions and constants).

    ``dotted`` are list and dict subclasses treated as lists and dicts, the dicts' keys
    also read as attributes (xacro's ``YamlListWrapper``, ``YamlDictWrapper``);
    ``scopes`` the types of a file's namespaces (``ns.NAME``), read through
    ``scope_lookup(scope, name)`` (``KeyError`` when absent).
    """

    def __init__(
        self,
        lookup: Callable[[str], Any],
        names: Mapping[str, Any],
        *,
        dotted: tuple[type, ...] = (),
        scopes: tuple[type, ...] = (),
        scope_lookup: Callable[[Any, str], Any] | None = None,
    ) -> None:
        self.lookup = lookup
        self.names = names
        self.dotted = dotted
        self.scopes = scopes
        self.scope_lookup = scope_lookup
        self.steps = 0
        self.expr = ""

    # -- entry

    def evaluate(self, expr: str) -> Any:
        """The value of ``expr``; :class:`ExpressionError` when refused or failing."""
        self.expr = expr.strip()
        self.steps = 0
        try:
            tree = ast.parse(self.expr, mode="eval")
        except SyntaxError as exc:
            raise ExpressionError(f"'{self._short()}': not an expression ({exc.msg})") from None
        except (RecursionError, MemoryError, ValueError):
            raise ExpressionError(f"'{self._short()}': too deeply nested") from None
        try:
            return self._eval(tree.body, {})
        except ExpressionError as exc:
            raise ExpressionError(f"'{self._short()}': {exc}") from None
        except _VALUE_ERRORS as exc:
            if isinstance(exc, RecursionError):
                message = "too deeply nested"
            elif isinstance(exc, MemoryError):
                message = "out of memory"
            else:
                message = f"{type(exc).__name__}: {exc}"
            raise ExpressionError(f"'{self._short()}': {message}") from None

    def _short(self) -> str:
        return self.expr if len(self.expr) <= 200 else self.expr[:200] + "..."

    # -- nodes

    def _eval(self, node: ast.AST, local: dict[str, Any]) -> Any:
        self.steps += 1
        if self.steps > MAX_STEPS:
            raise ExpressionError(f"over {MAX_STEPS} evaluation steps; refused")
        method = getattr(self, "_" + type(node).__name__, None)
        if method is None:
            raise ExpressionError(f"{_describe(node)} is not allowed in xacro expressions")
        return method(node, local)

    def _Constant(self, node: ast.Constant, local: dict[str, Any]) -> Any:
        if type(node.value) not in _SCALARS:
            raise ExpressionError(f"the literal {node.value!r} is not allowed")
        return _checked(node.value, "a literal")

    def _Name(self, node: ast.Name, local: dict[str, Any]) -> Any:
        name = node.id
        if name.startswith("_"):
            raise ExpressionError(f"the name '{name}' is refused (names may not start with _)")
        if name in local:
            return local[name]
        try:
            return self._value(self.lookup(name), name)
        except KeyError:
            pass
        if name in self.names:
            return self.names[name]
        raise ExpressionError(f"name '{name}' is not defined")

    def _value(self, value: Any, name: str) -> Any:
        """A value from the file's names, if it is of a type expressions may hold."""
        if self._holdable(value):
            return value
        raise ExpressionError(f"'{name}' holds a {type(value).__name__}, not a value")

    def _holdable(self, value: Any) -> bool:
        return (
            type(value) in _SCALARS
            or type(value) in _CONTAINERS
            or isinstance(value, (*self.dotted, *self.scopes, SafeFunction, _Method, Namespace))
            or type(value) in _VIEWS
            or _is_plain_data(value)
        )

    def _BinOp(self, node: ast.BinOp, local: dict[str, Any]) -> Any:
        op = _BINOPS.get(type(node.op))
        if op is None:
            raise ExpressionError(f"the operator {type(node.op).__name__} is not allowed")
        left = self._eval(node.left, local)
        right = self._eval(node.right, local)
        _precheck(type(node.op), left, right)
        return _checked(op(left, right), "the result")

    def _UnaryOp(self, node: ast.UnaryOp, local: dict[str, Any]) -> Any:
        return _UNARY[type(node.op)](self._eval(node.operand, local))

    def _BoolOp(self, node: ast.BoolOp, local: dict[str, Any]) -> Any:
        is_and = isinstance(node.op, ast.And)
        value: Any = None
        for item in node.values:
            value = self._eval(item, local)
            if bool(value) != is_and:
                return value
        return value

    def _Compare(self, node: ast.Compare, local: dict[str, Any]) -> Any:
        left = self._eval(node.left, local)
        for op, right_node in zip(node.ops, node.comparators):
            right = self._eval(right_node, local)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp, local: dict[str, Any]) -> Any:
        if self._eval(node.test, local):
            return self._eval(node.body, local)
        return self._eval(node.orelse, local)

    def _items(self, nodes: Iterable[ast.expr], local: dict[str, Any]) -> list[Any]:
        items: list[Any] = []
        for item in nodes:
            if isinstance(item, ast.Starred):
                items.extend(self._iterate(self._eval(item.value, local)))
            else:
                items.append(self._eval(item, local))
            if len(items) > MAX_ITEMS:
                raise ExpressionError(f"over {MAX_ITEMS} items; refused")
        return items

    def _List(self, node: ast.List, local: dict[str, Any]) -> Any:
        return _checked(self._items(node.elts, local), "a list")

    def _Tuple(self, node: ast.Tuple, local: dict[str, Any]) -> Any:
        return _checked(tuple(self._items(node.elts, local)), "a tuple")

    def _Set(self, node: ast.Set, local: dict[str, Any]) -> Any:
        return _checked(set(self._items(node.elts, local)), "a set")

    def _Dict(self, node: ast.Dict, local: dict[str, Any]) -> Any:
        result: dict[Any, Any] = {}
        for key, value in zip(node.keys, node.values):
            if key is None:  # {**other}
                other = self._eval(value, local)
                if not (type(other) is dict or isinstance(other, self.dotted)):
                    raise ExpressionError("** needs a dict")
                result.update(other)
            else:
                result[self._eval(key, local)] = self._eval(value, local)
        return _checked(result, "a dict")

    def _iterate(self, value: Any) -> Iterable[Any]:
        """The items of a value expressions may iterate (never a generator of Python)."""
        if type(value) in _ITERABLE or isinstance(value, self.dotted):
            return value
        raise ExpressionError(f"a {type(value).__name__} cannot be iterated")

    def _Subscript(self, node: ast.Subscript, local: dict[str, Any]) -> Any:
        value = self._eval(node.value, local)
        index = self._eval(node.slice, local)
        if isinstance(value, self.scopes) and self.scope_lookup is not None:
            if not isinstance(index, str) or index.startswith("_"):
                raise ExpressionError(f"a namespace key must be a name, not {index!r}")
            return self._value(self.scope_lookup(value, index), index)
        if not (type(value) in (str, list, tuple, dict) or isinstance(value, self.dotted)):
            raise ExpressionError(f"a {type(value).__name__} cannot be subscripted")
        if not isinstance(index, (int, str, float, tuple, slice, type(None))):
            raise ExpressionError(f"a {type(index).__name__} is not an index")
        return self._value(value[index], "the item")

    def _Slice(self, node: ast.Slice, local: dict[str, Any]) -> Any:
        parts = [
            None if p is None else self._eval(p, local) for p in (node.lower, node.upper, node.step)
        ]
        for part in parts:
            if part is not None and not _is_int(part):
                raise ExpressionError("slice bounds must be integers")
        return slice(*parts)

    def _Attribute(self, node: ast.Attribute, local: dict[str, Any]) -> Any:
        name = node.attr
        if name.startswith("_"):
            raise ExpressionError(
                f"the attribute '{name}' is refused (attributes may not start with _)"
            )
        value = self._eval(node.value, local)
        if isinstance(value, Namespace):
            if name in value.members:
                return value.members[name]
            raise ExpressionError(f"'{value.name}.{name}' is not available")
        if isinstance(value, self.scopes) and self.scope_lookup is not None:
            try:
                return self._value(self.scope_lookup(value, name), name)
            except KeyError:
                pass
            if name in self.names:
                return self.names[name]
            raise ExpressionError(f"name '{name}' is not defined in the namespace")
        for kind, allowed in METHODS.items():
            same = type(value) is kind or isinstance(value, self.dotted)
            if same and isinstance(value, kind) and name in allowed:
                return _Method(value, name)
        if isinstance(value, self.dotted) and isinstance(value, dict):
            # Python looks up the dict's own attributes first, then the key.
            if hasattr(dict, name):
                raise ExpressionError(f"the dict method '{name}' is not allowed")
            return self._value(getattr(value, name), name)
        raise ExpressionError(f"the attribute '{name}' of a {type(value).__name__} is not allowed")

    def _Call(self, node: ast.Call, local: dict[str, Any]) -> Any:
        fn = self._eval(node.func, local)
        if not isinstance(fn, (SafeFunction, _Method)):
            raise ExpressionError(f"a {type(fn).__name__} cannot be called")
        args = self._items(node.args, local)
        kwargs: dict[str, Any] = {}
        for keyword in node.keywords:
            if keyword.arg is None:
                extra = self._eval(keyword.value, local)
                if not isinstance(extra, dict) or not all(isinstance(k, str) for k in extra):
                    raise ExpressionError("** in a call needs a dict of names")
                kwargs.update(extra)
            else:
                kwargs[keyword.arg] = self._eval(keyword.value, local)
        if any(k.startswith("_") for k in kwargs):
            raise ExpressionError("keyword arguments may not start with _")
        return self._value(fn(*args, **kwargs), "the result")

    # -- comprehensions

    def _comprehend(
        self, generators: list[ast.comprehension], local: dict[str, Any], emit: Callable
    ) -> None:
        def loop(index: int, scope: dict[str, Any]) -> None:
            if index == len(generators):
                emit(scope)
                return
            gen = generators[index]
            if gen.is_async:
                raise ExpressionError("async comprehensions are not allowed")
            for item in self._iterate(self._eval(gen.iter, scope)):
                self.steps += 1
                if self.steps > MAX_STEPS:
                    raise ExpressionError(f"over {MAX_STEPS} evaluation steps; refused")
                inner = dict(scope)
                self._bind(gen.target, item, inner)
                if all(self._eval(cond, inner) for cond in gen.ifs):
                    loop(index + 1, inner)

        loop(0, dict(local))

    def _bind(self, target: ast.AST, value: Any, scope: dict[str, Any]) -> None:
        if isinstance(target, ast.Name):
            if target.id.startswith("_"):
                raise ExpressionError(f"the name '{target.id}' is refused")
            scope[target.id] = value
        elif isinstance(target, (ast.Tuple, ast.List)):
            items = list(self._iterate(value))
            if len(items) != len(target.elts):
                raise ExpressionError("cannot unpack: wrong number of values")
            for sub, item in zip(target.elts, items):
                self._bind(sub, item, scope)
        else:
            raise ExpressionError(f"{_describe(target)} is not a loop name")

    def _collect(self, node: Any, local: dict[str, Any]) -> list[Any]:
        out: list[Any] = []

        def emit(scope: dict[str, Any]) -> None:
            out.append(self._eval(node.elt, scope))
            if len(out) > MAX_ITEMS:
                raise ExpressionError(f"over {MAX_ITEMS} items; refused")

        self._comprehend(node.generators, local, emit)
        return out

    def _ListComp(self, node: ast.ListComp, local: dict[str, Any]) -> Any:
        return _checked(self._collect(node, local), "a list")

    def _GeneratorExp(self, node: ast.GeneratorExp, local: dict[str, Any]) -> Any:
        return _checked(self._collect(node, local), "a list")

    def _SetComp(self, node: ast.SetComp, local: dict[str, Any]) -> Any:
        return _checked(set(self._collect(node, local)), "a set")

    def _DictComp(self, node: ast.DictComp, local: dict[str, Any]) -> Any:
        out: dict[Any, Any] = {}

        def emit(scope: dict[str, Any]) -> None:
            out[self._eval(node.key, scope)] = self._eval(node.value, scope)
            if len(out) > MAX_ITEMS:
                raise ExpressionError(f"over {MAX_ITEMS} items; refused")

        self._comprehend(node.generators, local, emit)
        return _checked(out, "a dict")


def _is_plain_data(value: Any) -> bool:
    """Scalars YAML gives besides numbers and strings (dates, times)."""
    import datetime

    return type(value) in (datetime.date, datetime.datetime, datetime.time)


def _describe(node: ast.AST) -> str:
    names = {
        "Lambda": "a lambda",
        "JoinedStr": "an f-string",
        "FormattedValue": "an f-string",
        "NamedExpr": "an assignment (:=)",
        "Await": "await",
        "Yield": "yield",
        "YieldFrom": "yield",
        "Starred": "a * outside a call or literal",
    }
    return names.get(type(node).__name__, f"the construct {type(node).__name__}")


def _precheck(op: type, left: Any, right: Any) -> None:
    """Refuse before computing what would be over the caps (the computation itself
    would take the memory or time)."""
    if op is ast.Pow and _is_int(left) and _is_int(right) and right > 0:
        if abs(left) > 1 and right * math.log2(abs(left)) > MAX_INT_BITS:
            raise ExpressionError(f"a power over {MAX_INT_BITS} bits is refused")
    elif op is ast.Mult:
        for seq, n in ((left, right), (right, left)):
            length = _length(seq)
            if length is not None and _is_int(n) and length * n > MAX_STR:
                raise ExpressionError(f"a repetition over {MAX_STR} items is refused")
        bits = left.bit_length() + right.bit_length() if _is_int(left) and _is_int(right) else 0
        if bits > MAX_INT_BITS + 1:
            raise ExpressionError(f"an integer over {MAX_INT_BITS} bits is refused")
    elif op is ast.LShift and _is_int(left) and _is_int(right):
        if right > MAX_INT_BITS or left.bit_length() + right > MAX_INT_BITS:
            raise ExpressionError(f"an integer over {MAX_INT_BITS} bits is refused")
    elif op is ast.Add:
        a, b = _length(left), _length(right)
        if a is not None and b is not None and a + b > MAX_STR:
            raise ExpressionError(f"a value over {MAX_STR} items is refused")
    elif op is ast.Mod and isinstance(left, str):
        for match in _PERCENT.finditer(left):
            width, precision = match.group(1), match.group(2)
            if "*" in (width, precision):
                raise ExpressionError("'%*' (a width from the arguments) is refused")
            for number in (width, precision):
                if number and int(number) > MAX_WIDTH:
                    raise ExpressionError(f"a % width over {MAX_WIDTH} is refused")


# ---------------------------------------------------------------- xacro's hooks

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


def _no_eval(*_: Any, **__: Any) -> Any:
    raise ExpressionError("Python evaluation is disabled for xacro files")


def xacro_evaluators(xacro: Any, substitution_args: Any) -> tuple[Callable, Callable]:
    """Replacements for ``xacro.safe_eval(expr, symbols)`` and
    ``substitution_args._eval(expr, context)`` (``$(eval ...)``) built from the
    installed xacro module's own tables and functions."""
    table = xacro.Table
    root = xacro._global_symbols
    ns = dict.__getitem__(root, "xacro")
    xacro_ns = Namespace(
        "xacro",
        {
            name: SafeFunction(
                f"xacro.{name}",
                dict.__getitem__(ns, name),
                _dotify_guard if name == "dotify" else None,
            )
            for name in XACRO_NAMESPACE
            if dict.__contains__(ns, name)
        },
    )
    names = default_names()
    names["xacro"] = xacro_ns
    for name in XACRO_DIRECT:
        if dict.__contains__(root, name):
            names[name] = SafeFunction(
                name, dict.__getitem__(root, name), _dotify_guard if name == "dotify" else None
            )
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
