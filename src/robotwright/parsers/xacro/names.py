"""What a xacro expression may call and read: Python's and ``math``'s functions on an
allow-list, each wrapped in a guard that refuses work or values over the limits (huge
integers, strings, lists, widths) before it runs."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
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
